#include "mesh/ply_reader.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "core/srgb.h"
#include "mesh/mesh.h"
#include "mesh/mesh_bytes.h"

namespace streamrt {

namespace {

/// A scalar type of the PLY header.
struct PlyType {
    int size = 0;  ///< bytes in a binary body
    bool is_float = false;
    bool is_signed = false;
    const char* name = "";
};

/// The PLY type named `word` (the classic names and their sized aliases); size 0: unknown.
PlyType ply_type(std::string_view word) {
    static constexpr struct {
        const char* classic;
        const char* sized;
        PlyType type;
    } kTypes[] = {
        {"char", "int8", {1, false, true, "char"}},      {"uchar", "uint8", {1, false, false, "uchar"}},
        {"short", "int16", {2, false, true, "short"}},   {"ushort", "uint16", {2, false, false, "ushort"}},
        {"int", "int32", {4, false, true, "int"}},       {"uint", "uint32", {4, false, false, "uint"}},
        {"float", "float32", {4, true, true, "float"}},  {"double", "float64", {8, true, true, "double"}},
    };
    for (const auto& t : kTypes)
        if (word == t.classic || word == t.sized) return t.type;
    return {};
}

struct PlyProperty {
    std::string name;
    bool is_list = false;
    PlyType count_type;  ///< lists only
    PlyType type;        ///< the value type (a list's items)
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> props;
    int line = 0, col = 0;              ///< of the `element` keyword (missing properties)
    int count_line = 0, count_col = 0;  ///< of the count (too many items)
};

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
    std::size_t body = 0;  ///< offset of the body's first byte
    int body_line = 0;     ///< line of the body's first byte (ASCII messages)
};

[[noreturn]] void fail_at(const std::string& name, int line, int col, const std::string& message) {
    throw std::runtime_error(name + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + message);
}

bool is_index_list(const PlyElement& e, const PlyProperty& p) {
    return e.name == "face" && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

/// A face's per-corner texture coordinates (MeshLab's `property list uchar float texcoord`:
/// u and v of each corner, in the order of its vertex list).
bool is_texcoord_list(const PlyElement& e, const PlyProperty& p) {
    return e.name == "face" && p.is_list && (p.name == "texcoord" || p.name == "texcoords");
}

/// The fewest body bytes one item of `e` can take: its exact size in binary without lists,
/// two characters per value in ASCII (a digit and a separator); a face's index list has at
/// least 3 entries (other lists may be empty).
std::uint64_t min_item_bytes(const PlyElement& e, bool ascii) {
    std::uint64_t n = 0;
    for (const PlyProperty& p : e.props) {
        const std::uint64_t items = is_index_list(e, p) ? 3 : 0;
        if (ascii) n += 2 * (1 + (p.is_list ? items : 0));
        else n += p.is_list ? std::uint64_t(p.count_type.size) + items * std::uint64_t(p.type.size)
                            : std::uint64_t(p.type.size);
    }
    return n;
}

PlyHeader parse_header(std::string_view bytes, const std::string& name) {
    PlyHeader h;
    std::size_t pos = 0;
    bool have_format = false;
    for (int line = 1;; ++line) {
        if (pos >= bytes.size()) fail_at(name, line, 1, "file ends before 'end_header'");
        std::size_t end = bytes.find('\n', pos);
        const std::size_t next = end == std::string_view::npos ? bytes.size() : end + 1;
        if (end == std::string_view::npos) end = bytes.size();
        std::string_view text = bytes.substr(pos, end - pos);
        if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
        struct Word {
            std::string_view text;
            int col;
        };
        std::vector<Word> words;
        for (std::size_t i = 0; i < text.size();) {
            if (text[i] == ' ' || text[i] == '\t') {
                ++i;
                continue;
            }
            std::size_t j = i;
            while (j < text.size() && text[j] != ' ' && text[j] != '\t') ++j;
            words.push_back({text.substr(i, j - i), int(i + 1)});
            i = j;
        }
        pos = next;
        const auto fail = [&](std::size_t w, const std::string& message) {
            fail_at(name, line, w < words.size() ? words[w].col : int(text.size() + 1), message);
        };
        const auto expect_words = [&](std::size_t n, const char* form) {
            if (words.size() < n) fail(words.size(), std::string("expected ") + form);
            if (words.size() > n) fail(n, "unexpected " + quote(words[n].text) + " after " + form);
        };
        if (line == 1) {
            if (words.size() != 1 || words[0].text != "ply") fail(0, "not a PLY file (the first line must be 'ply')");
            continue;
        }
        if (words.empty()) continue;
        const std::string_view key = words[0].text;
        if (key == "comment" || key == "obj_info") continue;
        if (key == "format") {
            expect_words(3, "'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
            if (have_format) fail(0, "a second 'format' line");
            if (words[1].text == "ascii") h.format = PlyFormat::Ascii;
            else if (words[1].text == "binary_little_endian") h.format = PlyFormat::BinaryLittle;
            else if (words[1].text == "binary_big_endian") h.format = PlyFormat::BinaryBig;
            else fail(1, "unknown PLY format " + quote(words[1].text));
            if (words[2].text != "1.0") fail(2, "unsupported PLY version " + quote(words[2].text) + " (1.0 is read)");
            have_format = true;
            continue;
        }
        if (!have_format) fail(0, "expected 'format' before " + quote(key));
        if (key == "element") {
            expect_words(3, "'element <name> <count>'");
            PlyElement e;
            e.name = std::string(words[1].text);
            const std::string_view c = words[2].text;
            const auto [ptr, ec] = std::from_chars(c.data(), c.data() + c.size(), e.count);
            if (ec != std::errc() || ptr != c.data() + c.size())
                fail(2, "expected a count of items (0 or more), got " + quote(c));
            for (const PlyElement& o : h.elements)
                if (o.name == e.name) fail(1, "a second element " + quote(e.name));
            e.line = line, e.col = words[0].col;
            e.count_line = line, e.count_col = words[2].col;
            h.elements.push_back(std::move(e));
            continue;
        }
        if (key == "property") {
            if (h.elements.empty()) fail(0, "'property' before any 'element'");
            PlyProperty p;
            std::size_t w = 1;
            if (words.size() > 1 && words[1].text == "list") {
                expect_words(5, "'property list <count type> <item type> <name>'");
                p.is_list = true;
                p.count_type = ply_type(words[2].text);
                if (p.count_type.size == 0) fail(2, "unknown property type " + quote(words[2].text));
                if (p.count_type.is_float) fail(2, "a list's count type must be an integer type, got " + quote(words[2].text));
                w = 3;
            } else {
                expect_words(3, "'property <type> <name>'");
            }
            p.type = ply_type(words[w].text);
            if (p.type.size == 0) fail(w, "unknown property type " + quote(words[w].text));
            p.name = std::string(words[w + 1].text);
            PlyElement& e = h.elements.back();
            for (const PlyProperty& o : e.props)
                if (o.name == p.name) fail(w + 1, "a second property " + quote(p.name) + " in element " + quote(e.name));
            const bool position = e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z");
            if (position && p.is_list) fail(w + 1, "vertex property " + quote(p.name) + " must be a number, not a list");
            const bool indices = e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index");
            if (indices && !p.is_list) fail(w + 1, quote(p.name) + " must be a list ('property list uchar int " + p.name + "')");
            if (indices && p.type.is_float) fail(w, "vertex indices must have an integer type, got " + quote(words[w].text));
            e.props.push_back(std::move(p));
            continue;
        }
        if (key == "end_header") {
            expect_words(1, "'end_header'");
            h.body = pos;
            h.body_line = line + 1;
            break;
        }
        fail(0, "unexpected " + quote(key) + " in the PLY header");
    }
    const auto has = [](const PlyElement& e, std::initializer_list<const char*> names) {
        for (const PlyProperty& p : e.props)
            for (const char* n : names)
                if (p.name == n) return true;
        return false;
    };
    const bool ascii = h.format == PlyFormat::Ascii;
    const std::uint64_t body_bytes = bytes.size() - h.body;
    std::uint64_t needed = 0;  // the fewest body bytes of all the elements so far
    bool vertex = false, face = false;
    for (const PlyElement& e : h.elements) {
        if (e.name == "vertex") {
            vertex = true;
            for (const char* axis : {"x", "y", "z"})
                if (!has(e, {axis})) fail_at(name, e.line, e.col, "element 'vertex' has no property '" + std::string(axis) + "'");
            if (e.count > std::numeric_limits<std::uint32_t>::max())
                fail_at(name, e.count_line, e.count_col, "more vertices than 32-bit vertex numbers can address");
        }
        if (e.name == "face") {
            face = true;
            if (!has(e, {"vertex_indices", "vertex_index"}))
                fail_at(name, e.line, e.col, "element 'face' has no property list 'vertex_indices'");
        }
        // Refused before anything is allocated: a hostile count must not reserve memory.
        const std::uint64_t item = min_item_bytes(e, ascii);
        const std::uint64_t room = ascii ? body_bytes + 1 : body_bytes;  // the last ASCII value needs no separator
        if (item > 0 && (e.count > (room - std::min(room, needed)) / item))
            fail_at(name, e.count_line, e.count_col,
                    "element " + quote(e.name) + " declares " + std::to_string(e.count) + " items, more than the " +
                        std::to_string(body_bytes) + " bytes after the header can hold");
        needed += e.count * item;
    }
    if (!vertex) fail_at(name, h.body_line - 1, 1, "the header declares no element 'vertex'");
    if (!face) fail_at(name, h.body_line - 1, 1, "the header declares no element 'face'");
    return h;
}

/// Values of an ASCII body, one whitespace-separated word at a time.
class AsciiBody {
public:
    AsciiBody(std::string_view bytes, const PlyHeader& h, const std::string& name)
        : bytes_(bytes), pos_(h.body), line_start_(h.body), line_(h.body_line), name_(name) {}

    void begin_item(const std::string& element, std::uint64_t k) { element_ = &element, item_ = k; }

    std::int64_t read_int(const PlyType& t) {
        const std::string_view w = word();
        std::int64_t v = 0;
        const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
        if (ec != std::errc() || ptr != w.data() + w.size())
            fail("expected an integer (" + std::string(t.name) + "), got " + quote(w));
        const std::int64_t lo = t.is_signed ? -(std::int64_t(1) << (8 * t.size - 1)) : 0;
        const std::int64_t hi = t.is_signed ? (std::int64_t(1) << (8 * t.size - 1)) - 1 : (std::int64_t(1) << (8 * t.size)) - 1;
        if (v < lo || v > hi) fail(quote(w) + " is out of range for " + t.name);
        return v;
    }
    double read_number(const PlyType& t) {
        if (!t.is_float) return double(read_int(t));
        const std::string_view w = word();
        double v = 0;
        const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
        if (ec != std::errc() || ptr != w.data() + w.size()) fail("expected a number (" + std::string(t.name) + "), got " + quote(w));
        return v;
    }
    void skip(const PlyType& t) { read_number(t); }
    void skip_list(std::uint64_t n, const PlyType& t) {
        for (std::uint64_t i = 0; i < n; ++i) skip(t);
    }
    [[noreturn]] void fail(const std::string& message) const { fail_at(name_, word_line_, word_col_, message); }

private:
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
    std::string_view word() {
        while (pos_ < bytes_.size() && is_space(bytes_[pos_])) {
            if (bytes_[pos_] == '\n') line_start_ = pos_ + 1, ++line_;
            ++pos_;
        }
        word_line_ = line_, word_col_ = int(pos_ - line_start_ + 1);
        if (pos_ >= bytes_.size())
            fail("file ends inside element " + quote(*element_) + " item " + std::to_string(item_));
        const std::size_t start = pos_;
        while (pos_ < bytes_.size() && !is_space(bytes_[pos_])) ++pos_;
        return bytes_.substr(start, pos_ - start);
    }

    std::string_view bytes_;
    std::size_t pos_, line_start_;
    int line_;
    int word_line_ = 0, word_col_ = 0;
    const std::string& name_;
    const std::string* element_ = nullptr;
    std::uint64_t item_ = 0;
};

/// Values of a binary body in the file's byte order.
class BinaryBody {
public:
    BinaryBody(std::string_view bytes, const PlyHeader& h, const std::string& name)
        : bytes_(bytes), pos_(h.body), value_at_(h.body), swap_((h.format == PlyFormat::BinaryBig) != (std::endian::native == std::endian::big)),
          name_(name) {}

    void begin_item(const std::string& element, std::uint64_t k) { element_ = &element, item_ = k; }

    std::int64_t read_int(const PlyType& t) {
        const double v = read_number(t);
        return std::int64_t(v);  // integer types of at most 32 bits: exact in a double
    }
    double read_number(const PlyType& t) {
        unsigned char b[8];
        take(b, std::size_t(t.size));
        if (swap_) std::reverse(b, b + t.size);
        const auto as = [&](auto v) {
            std::memcpy(&v, b, sizeof v);
            return double(v);
        };
        switch (t.size) {
        case 1: return t.is_signed ? as(std::int8_t()) : as(std::uint8_t());
        case 2: return t.is_signed ? as(std::int16_t()) : as(std::uint16_t());
        case 4: return t.is_float ? as(float()) : t.is_signed ? as(std::int32_t()) : as(std::uint32_t());
        default: return as(double());
        }
    }
    void skip(const PlyType& t) { skip_list(1, t); }
    void skip_list(std::uint64_t n, const PlyType& t) {
        value_at_ = pos_;
        if (n > (bytes_.size() - pos_) / std::uint64_t(t.size)) ends(n * std::uint64_t(t.size));
        pos_ += std::size_t(n) * std::size_t(t.size);
    }
    [[noreturn]] void fail(const std::string& message) const {
        throw std::runtime_error(name_ + ": element " + *element_ + " " + std::to_string(item_) + " (byte offset " +
                                 std::to_string(value_at_) + "): " + message);
    }

private:
    void take(unsigned char* out, std::size_t n) {
        value_at_ = pos_;
        if (bytes_.size() - pos_ < n) ends(n);
        std::memcpy(out, bytes_.data() + pos_, n);
        pos_ += n;
    }
    [[noreturn]] void ends(std::uint64_t n) const {
        fail("file ends inside the item (" + std::to_string(n) + " more bytes needed, " +
             std::to_string(bytes_.size() - pos_) + " left)");
    }

    std::string_view bytes_;
    std::size_t pos_, value_at_;
    bool swap_;
    const std::string& name_;
    const std::string* element_ = nullptr;
    std::uint64_t item_ = 0;
};

/// A vertex colour component as linear light: an integer type holds an sRGB code (0 - 255 for
/// uchar, 0 - 65535 for ushort: the full range of its type is white), a float type a linear
/// value, as written. Negative or non-finite values are errors (an integer word outside its
/// type was refused when read).
template <class Body>
float linear_color(Body& body, double value, const PlyType& t) {
    if (!std::isfinite(value) || value < 0.0) body.fail("vertex colour " + std::to_string(value) + " is not a finite value >= 0");
    if (t.is_float) return float(value);
    if (t.size == 1 && !t.is_signed) return srgb_to_linear(std::uint8_t(value));
    const double top = std::ldexp(1.0, 8 * t.size - (t.is_signed ? 1 : 0)) - 1.0;
    return float(srgb_eotf(std::min(1.0, value / top)));
}

/// Reads the body's elements in header order into `out`.
template <class Body>
void read_body(Body& body, const PlyHeader& h, const PlyReadOptions& options, PlyData& out) {
    std::uint64_t vertex_count = 0;
    for (const PlyElement& e : h.elements)
        if (e.name == "vertex") vertex_count = e.count;
    for (const PlyElement& e : h.elements) {
        // An element without properties holds nothing and takes no bytes, whatever its count
        // (a count the header check cannot bound: looping over 4e9 empty items took minutes).
        if (e.props.empty()) continue;
        const bool vertex = e.name == "vertex", face = e.name == "face";
        // Per property: where a vertex keeps it (0-2 position, 3-5 normal, 6-7 texture
        // coordinates under any of their usual names, 8-10 colour, -1 skipped).
        std::vector<int> slot(e.props.size(), -1);
        bool normals = true, uvs = true, colors = true;
        if (vertex) {
            static const struct {
                const char* name;
                int slot;
            } kSlots[] = {{"x", 0},         {"y", 1},         {"z", 2},         {"nx", 3},        {"ny", 4},
                          {"nz", 5},        {"u", 6},         {"s", 6},         {"texture_u", 6}, {"texture_s", 6},
                          {"v", 7},         {"t", 7},         {"texture_v", 7}, {"texture_t", 7},
                          {"red", 8},       {"green", 9},     {"blue", 10},     {"diffuse_red", 8},
                          {"diffuse_green", 9}, {"diffuse_blue", 10}};
            for (std::size_t p = 0; p < e.props.size(); ++p)
                for (const auto& k : kSlots)
                    if (!e.props[p].is_list && e.props[p].name == k.name) slot[p] = k.slot;
            for (int s = 3; s < 6; ++s) normals = normals && std::count(slot.begin(), slot.end(), s) == 1;
            for (int s = 6; s < 8; ++s) uvs = uvs && std::count(slot.begin(), slot.end(), s) == 1;
            for (int s = 8; s < 11; ++s) colors = colors && std::count(slot.begin(), slot.end(), s) == 1;
            uvs = uvs && options.keep_uv;
            colors = colors && options.keep_colors;
            if (options.budget)
                options.budget->need(double(e.count) * sizeof(float) *
                                         (3 + (normals ? 3 : 0) + (uvs ? 2 : 0) + (colors ? 3 : 0)),
                                     "its " + std::to_string(e.count) + " vertices");
            out.positions.reserve(3 * std::size_t(e.count));  // bounded by the file's length (parse_header)
            if (normals) out.normals.reserve(3 * std::size_t(e.count));
            if (uvs) out.uvs.reserve(2 * std::size_t(e.count));
            if (colors) out.colors.reserve(3 * std::size_t(e.count));
        }
        const PlyProperty* indices = nullptr;    // the first index list of a face
        const PlyProperty* texcoords = nullptr;  // and its first texture coordinate list
        for (const PlyProperty& p : e.props) {
            if (!indices && is_index_list(e, p)) indices = &p;
            if (!texcoords && options.keep_uv && is_texcoord_list(e, p)) texcoords = &p;
        }
        // A face of n corners is n - 2 triangles: counted as one here, the rest once read.
        if (face && options.budget)
            options.budget->need(double(e.count) * (3 * sizeof(std::uint32_t) + (texcoords ? 6 * sizeof(float) : 0)),
                                 "its " + std::to_string(e.count) + " faces");
        if (face) out.triangles.reserve(3 * std::size_t(e.count));
        if (texcoords) out.corner_uv.reserve(6 * std::size_t(e.count));
        std::vector<std::uint32_t> corners;  // one face's vertex numbers
        std::vector<float> corner_uv;        // and its texcoord list
        for (std::uint64_t k = 0; k < e.count; ++k) {
            body.begin_item(e.name, k);
            double v[11] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
            const PlyType* color_type[3] = {nullptr, nullptr, nullptr};
            corners.clear();
            corner_uv.clear();
            for (std::size_t p = 0; p < e.props.size(); ++p) {
                const PlyProperty& prop = e.props[p];
                if (!prop.is_list) {
                    if (slot[p] >= 0) v[slot[p]] = body.read_number(prop.type);
                    else body.skip(prop.type);
                    if (slot[p] >= 8) color_type[slot[p] - 8] = &prop.type;
                    continue;
                }
                const std::int64_t n = body.read_int(prop.count_type);
                if (n < 0) body.fail("a list of " + std::to_string(n) + " items");
                if (&prop == texcoords) {
                    for (std::int64_t j = 0; j < n; ++j) {
                        const float c = float(body.read_number(prop.type));
                        if (!std::isfinite(c)) body.fail("texture coordinate is not finite");
                        corner_uv.push_back(c);
                    }
                    continue;
                }
                if (&prop != indices) {
                    body.skip_list(std::uint64_t(n), prop.type);
                    continue;
                }
                if (n < 3) body.fail("a face needs at least 3 vertices, got " + std::to_string(n));
                for (std::int64_t j = 0; j < n; ++j) {
                    const std::int64_t index = body.read_int(prop.type);
                    if (index < 0 || std::uint64_t(index) >= vertex_count)
                        body.fail("vertex index " + std::to_string(index) + " is not one of the " +
                                  std::to_string(vertex_count) + " vertices");
                    corners.push_back(std::uint32_t(index));
                }
            }
            if (face) {
                if (texcoords && corner_uv.size() != 2 * corners.size())
                    body.fail("a face of " + std::to_string(corners.size()) + " vertices needs " +
                              std::to_string(2 * corners.size()) + " texture coordinates, got " +
                              std::to_string(corner_uv.size()));
                // Fan triangulation: (first, previous, current) for every corner after the second.
                for (std::size_t j = 2; j < corners.size(); ++j) {
                    out.triangles.insert(out.triangles.end(), {corners[0], corners[j - 1], corners[j]});
                    if (texcoords)
                        out.corner_uv.insert(out.corner_uv.end(), {corner_uv[0], corner_uv[1], corner_uv[2 * j - 2],
                                                                   corner_uv[2 * j - 1], corner_uv[2 * j],
                                                                   corner_uv[2 * j + 1]});
                }
                continue;
            }
            if (!vertex) continue;
            for (int a = 0; a < 3; ++a)
                if (!std::isfinite(float(v[a]))) body.fail("vertex position is not finite");
            out.positions.insert(out.positions.end(), {float(v[0]), float(v[1]), float(v[2])});
            if (normals) out.normals.insert(out.normals.end(), {float(v[3]), float(v[4]), float(v[5])});
            if (uvs) {
                if (!std::isfinite(float(v[6])) || !std::isfinite(float(v[7])))
                    body.fail("texture coordinate is not finite");
                out.uvs.insert(out.uvs.end(), {float(v[6]), float(v[7])});
            }
            if (colors)
                for (int c = 0; c < 3; ++c) out.colors.push_back(linear_color(body, v[8 + c], *color_type[c]));
        }
    }
}

}  // namespace

PlyData parse_ply(std::string_view bytes, const std::string& name, const PlyReadOptions& options) {
    const PlyHeader h = parse_header(bytes, name);
    PlyData out;
    if (h.format == PlyFormat::Ascii) {
        AsciiBody body(bytes, h, name);
        read_body(body, h, options, out);
    } else {
        BinaryBody body(bytes, h, name);
        read_body(body, h, options, out);
    }
    return out;
}

std::shared_ptr<const Mesh> load_ply_mesh(const std::string& path, bool with_uv, bool with_colors) {
    MemoryBudget budget = MemoryBudget::now();  // read as this file's reading starts
    PlyData data;
    {
        const MeshBytes bytes(path, budget);  // mapped, or inflated from a .gz file
        data = parse_ply(bytes.text(), path, {.keep_uv = with_uv, .keep_colors = with_colors, .budget = &budget});
        budget.release(double(bytes.text().size()));  // given back before the mesh is built
    }
    const std::size_t faces = data.triangles.size() / 3;
    if (faces == 0) throw std::runtime_error("PLY file has no faces");  // before anything is built
    std::vector<float> corner_uv;
    if (with_uv) {
        if (!data.corner_uv.empty()) {
            corner_uv = data.corner_uv;
        } else if (!data.uvs.empty()) {
            corner_uv.reserve(6 * faces);
            for (const std::uint32_t i : data.triangles)
                corner_uv.insert(corner_uv.end(), {data.uvs[2 * std::size_t(i)], data.uvs[2 * std::size_t(i) + 1]});
        } else {
            throw std::runtime_error(
                "a texture needs texture coordinates, and this PLY file has none (vertex properties u v, s t or "
                "texture_u texture_v, or a face list 'texcoord')");
        }
    }
    if (with_colors && data.colors.empty())
        throw std::runtime_error(
            "vertex_colors=true needs colours at the vertices, and this PLY file has none (vertex properties red "
            "green blue)");
    budget.need(Mesh::build_bytes(data.positions.size() / 3, faces, !corner_uv.empty(), !data.colors.empty()),
                "building its " + std::to_string(faces) + " triangles");
    auto mesh = Mesh::build(path, std::move(data.positions), std::move(data.triangles), {}, corner_uv, data.normals, data.colors);
    if (mesh->triangle_count() == 0)
        throw std::runtime_error("PLY file has no triangles of non-zero area (" + std::to_string(faces) + " degenerate)");
    return mesh;
}

bool is_ply_path(const std::string& gz_path) {
    const std::string path = without_gzip_suffix(gz_path);
    if (path.size() < 4) return false;
    std::string ext = path.substr(path.size() - 4);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".ply";
}

std::shared_ptr<const Mesh> load_mesh_file(const std::string& path, bool with_uv, bool with_colors) {
    if (is_ply_path(path)) return load_ply_mesh(path, with_uv, with_colors);
    return load_obj_mesh(path, with_uv, with_colors);
}

}  // namespace streamrt
