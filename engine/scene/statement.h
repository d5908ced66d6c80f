#pragma once
// The scene reader's lexing and values (docs/scene-format.md): one line cut into tokens with
// their columns, `key=value` arguments, and the checked conversions of values (numbers,
// vectors, colours, ...), each failing with a SceneError at the exact file:line:col. A line
// allocates nothing: tokens and arguments are views kept in scratch lists reused from line
// to line. Internal to the reader (scene/parser*.cpp).
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/format_number.h"
#include "core/nearest_name.h"
#include "core/error.h"
#include "core/transform.h"
#include "scene/scene.h"

namespace streamrt::scene_reader {

constexpr int kMaxIncludeDepth = 32;  // nested includes below the top-level file
constexpr int kMaxFiles = 1000;       // files read in total, top-level included
constexpr double kSingular = 1e-12;   // relative_determinant threshold

struct Token {
    std::string_view text;
    int column = 0;  // 1-based byte column
};

struct Arg {
    std::string_view key;
    int key_col = 0;
    std::string_view value;
    int value_col = 0;
};

/// Byte classes for the lexer's inner loops: one table load per byte instead of six tests.
enum : unsigned char { kSpace = 1, kHash = 2 };
constexpr auto kByteClass = [] {
    std::array<unsigned char, 256> t{};
    for (const char c : {' ', '\t', '\r', '\v', '\f'}) t[static_cast<unsigned char>(c)] = kSpace;
    t[static_cast<unsigned char>('#')] = kHash;
    return t;
}();
inline unsigned char byte_class(char c) { return kByteClass[static_cast<unsigned char>(c)]; }

/// a == b, the first byte tested before memcmp: most key comparisons fail on the length or
/// there, and this runs some twenty times a line.
inline bool same(std::string_view a, std::string_view b) {
    return a.size() == b.size() && (a.empty() || (a[0] == b[0] && std::memcmp(a.data(), b.data(), a.size()) == 0));
}

/// Splits one line (comment removed) into whitespace-separated tokens with their columns,
/// into `out` (reused from line to line, so a line allocates nothing).
inline void tokenize(std::string_view line, std::vector<Token>& out) {
    out.clear();
    const char* const begin = line.data();
    const char* const end = begin + line.size();
    const char* p = begin;
    // One scan: '#' ends the last token and the line, as if the line were cut there.
    while (p < end) {
        while (p < end && byte_class(*p) == kSpace) ++p;
        if (p >= end || *p == '#') break;
        const char* start = p;
        while (p < end && byte_class(*p) == 0) ++p;
        out.push_back({std::string_view(start, std::size_t(p - start)), int(start - begin) + 1});
    }
}

/// The first word of a line as tokenize() would find it ("" for a blank or comment line),
/// without building the token list: the cheap look the chunked first pass takes at a line.
inline std::string_view first_word(std::string_view line) {
    const char* p = line.data();
    const char* const end = p + line.size();
    while (p < end && byte_class(*p) == kSpace) ++p;
    const char* start = p;
    while (p < end && byte_class(*p) == 0) ++p;
    return std::string_view(start, std::size_t(p - start));
}

/// A finite double written entirely in `s` (an optional leading '+' is accepted).
inline std::optional<double> to_number(std::string_view s) {
    if (!s.empty() && s.front() == '+') {
        s.remove_prefix(1);
        if (!s.empty() && (s.front() == '+' || s.front() == '-')) return std::nullopt;
    }
    if (s.empty()) return std::nullopt;
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

/// "x,y,z": exactly three numbers (empty components and a fourth are refused).
inline std::optional<glm::dvec3> to_vec3(std::string_view s) {
    glm::dvec3 out{0.0};
    for (int i = 0; i < 3; ++i) {
        const auto comma = s.find(',');
        if ((comma == std::string_view::npos) != (i == 2)) return std::nullopt;
        const auto v = to_number(s.substr(0, comma));
        if (!v) return std::nullopt;
        out[i] = *v;
        if (i < 2) s.remove_prefix(comma + 1);
    }
    return out;
}

inline bool all_finite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

/// Not usable as Md: not finite, (nearly) singular, or with an inverse that overflows (a tiny
/// scale followed by a huge translation gives a finite Md whose Mi is not).
inline bool singular(const glm::dmat4& m) {
    if (!all_finite(m) || !(relative_determinant(m) >= kSingular)) return true;
    return !all_finite(glm::inverse(m));
}

/// One statement being read: its location, its word and (for keyed statements) its arguments.
/// `args` is the reader's scratch list, cleared here: no allocation per statement.
class Statement {
  public:
    Statement(const std::string& file, int line, Token word, std::vector<Arg>& scratch)
        : args(scratch), file_(&file), line_(line), word_(word) {
        args.clear();
    }

    [[noreturn]] void fail(int column, std::string_view msg) const {
        throw SceneError(SourceLoc{*file_, line_, column}, msg);
    }
    [[noreturn]] void fail_here(std::string_view msg) const { fail(word_.column, msg); }
    SourceLoc where() const { return SourceLoc{*file_, line_, word_.column}; }
    std::string_view word() const { return word_.text; }
    const std::string& file() const { return *file_; }
    int line() const { return line_; }

    std::vector<Arg>& args;

    /// Reads `key=value` tokens, rejecting missing '=', unknown and duplicate keys, and empty
    /// values, in the order they appear on the line.
    void read_args(const std::vector<Token>& toks, std::size_t first,
                   const std::vector<std::string_view>& allowed) {
        for (std::size_t i = first; i < toks.size(); ++i) {
            const Token& t = toks[i];
            const auto eq = t.text.find('=');
            if (eq == std::string_view::npos)
                fail(t.column, "expected key=value, got " + quote(t.text) + " (missing '=')");
            Arg a{t.text.substr(0, eq), t.column, t.text.substr(eq + 1), t.column + int(eq) + 1};
            if (a.key.empty()) fail(t.column, "missing key before '=' in " + quote(t.text));
            if (std::none_of(allowed.begin(), allowed.end(), [&](std::string_view k) { return same(k, a.key); })) {
                std::string msg = "unknown key " + quote(a.key) + " for '" + std::string(word()) + "'";
                if (const auto near = nearest_name(a.key, allowed)) msg += ": did you mean '" + *near + "'?";
                msg += " (expected one of:";
                for (auto k : allowed) (msg += ' ') += k;  // not " " + string: GCC 12's -Wrestrict false alarm
                msg += ")";
                fail(a.key_col, msg);
            }
            for (const Arg& prev : args)
                if (same(prev.key, a.key))
                    fail(a.key_col, "duplicate key " + quote(a.key) + " (first given at column " +
                                        std::to_string(prev.key_col) + ")");
            if (a.value.empty()) fail(a.value_col, "empty value for " + quote(a.key));
            args.push_back(a);
        }
    }

    const Arg* find(std::string_view key) const {
        for (const Arg& a : args)
            if (same(a.key, key)) return &a;
        return nullptr;
    }

    // ---- values -------------------------------------------------------------------------
    double number(const Arg& a) const {
        const auto v = to_number(a.value);
        if (!v) fail(a.value_col, "expected a number for " + quote(a.key) + ", got " + quote(a.value));
        return *v;
    }
    double at_least_zero(const Arg& a) const {
        const double v = number(a);
        if (!(v >= 0.0)) fail(a.value_col, quote(a.key) + " must be >= 0, got " + quote(a.value));
        return v;
    }
    double positive(const Arg& a) const {
        const double v = number(a);
        if (!(v > 0.0)) fail(a.value_col, quote(a.key) + " must be > 0, got " + quote(a.value));
        return v;
    }
    double in_closed(const Arg& a, double lo, double hi) const {
        const double v = number(a);
        if (!(v >= lo && v <= hi))
            fail(a.value_col, quote(a.key) + " must be in [" + fmt_num(lo) + ", " + fmt_num(hi) +
                                  "], got " + quote(a.value));
        return v;
    }
    double in_open(const Arg& a, double lo, double hi) const {
        const double v = number(a);
        if (!(v > lo && v < hi))
            fail(a.value_col, quote(a.key) + " must be in (" + fmt_num(lo) + ", " + fmt_num(hi) +
                                  "), got " + quote(a.value));
        return v;
    }
    int integer(const Arg& a, int lo, int hi) const {
        const auto v = to_number(a.value);
        if (!v) fail(a.value_col, "expected a number for " + quote(a.key) + ", got " + quote(a.value));
        if (*v != std::floor(*v))
            fail(a.value_col, "expected an integer for " + quote(a.key) + ", got " + quote(a.value));
        if (!(*v >= lo && *v <= hi))
            fail(a.value_col, quote(a.key) + " must be in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "], got " + quote(a.value));
        return int(*v);
    }
    glm::dvec3 vec3(const Arg& a) const {
        const auto v = to_vec3(a.value);
        if (!v)
            fail(a.value_col, "expected 3 comma-separated numbers x,y,z for " + quote(a.key) +
                                  ", got " + quote(a.value));
        return *v;
    }
    glm::dvec3 color(const Arg& a) const {
        const glm::dvec3 c = vec3(a);
        if (!(c.x >= 0.0 && c.y >= 0.0 && c.z >= 0.0))
            fail(a.value_col, "colour components of " + quote(a.key) + " must be >= 0, got " +
                                  quote(a.value));
        // Colours are single precision in the scene records and the stream engine.
        constexpr double kMaxColour = std::numeric_limits<float>::max();
        if (!(c.x <= kMaxColour && c.y <= kMaxColour && c.z <= kMaxColour))
            fail(a.value_col, "colour components of " + quote(a.key) + " must be at most 3.4e38, got " +
                                  quote(a.value));
        return c;
    }
    glm::dvec3 direction(const Arg& a) const {
        const glm::dvec3 d = vec3(a);
        const double len = glm::length(d);
        if (!(len > 0.0) || !std::isfinite(len))
            fail(a.value_col, quote(a.key) + " must be a non-zero vector, got " + quote(a.value));
        return d / len;
    }
    /// One of the enum's names (core/enum_names.h).
    template <class E, std::size_t N>
    E word(const Arg& a, const EnumName<E> (&names)[N]) const {
        if (const auto v = value_named(names, a.value)) return *v;
        fail(a.value_col, "expected " + names_list(names) + " for " + quote(a.key) + ", got " + quote(a.value));
    }
    bool boolean(const Arg& a) const {
        if (same(a.value, "true")) return true;
        if (!same(a.value, "false"))
            fail(a.value_col, "expected true or false for " + quote(a.key) + ", got " + quote(a.value));
        return false;
    }
    /// One number (uniform) or x,y,z; no zero component.
    glm::dvec3 scale(const Arg& a) const {
        glm::dvec3 s;
        if (a.value.find(',') == std::string_view::npos) {
            const auto v = to_number(a.value);
            if (!v)
                fail(a.value_col, "expected a number or x,y,z for " + quote(a.key) + ", got " +
                                      quote(a.value));
            s = glm::dvec3(*v);
        } else {
            s = vec3(a);
        }
        if (s.x == 0.0 || s.y == 0.0 || s.z == 0.0)
            fail(a.value_col, "scale components must be non-zero, got " + quote(a.value));
        return s;
    }

  private:
    const std::string* file_;  // outlives the statement: the reader's name for the file
    int line_;
    Token word_;
};

}  // namespace streamrt::scene_reader
