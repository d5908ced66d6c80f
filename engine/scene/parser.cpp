// The .cfg scene reader (docs/scene-format.md). One statement per line, `#` comments,
// `key=value` arguments; every mistake becomes a SceneError at the exact line and column of
// the offending token (the key, the value or the statement word).
//
// Speed (docs/architecture.md, "Scene reading"): the file is mapped, lines are cut with
// memchr and lexed into views kept in scratch vectors reused from line to line; a large file
// is cut into chunks at line ends, the rare non-shape statements run first in file order and
// the shapes of all chunks are parsed in parallel into their final slots of scene.objects.
#include "scene/parser.h"

#include "core/memory_advice.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mesh/mesh.h"
#include "parallel/parallelism.h"
#include "scene/animation.h"
#include "shapes/shapes.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

namespace streamrt {
namespace {

namespace fs = std::filesystem;

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

std::string fmt_num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

/// Byte classes for the lexer's inner loops: one table load per byte instead of six tests.
enum : unsigned char { kSpace = 1, kHash = 2 };
constexpr auto kByteClass = [] {
    std::array<unsigned char, 256> t{};
    for (const char c : {' ', '\t', '\r', '\v', '\f'}) t[static_cast<unsigned char>(c)] = kSpace;
    t[static_cast<unsigned char>('#')] = kHash;
    return t;
}();
unsigned char byte_class(char c) { return kByteClass[static_cast<unsigned char>(c)]; }

/// a == b, the first byte tested before memcmp: most key comparisons fail on the length or
/// there, and this runs some twenty times a line.
bool same(std::string_view a, std::string_view b) {
    return a.size() == b.size() && (a.empty() || (a[0] == b[0] && std::memcmp(a.data(), b.data(), a.size()) == 0));
}

/// Splits one line (comment removed) into whitespace-separated tokens with their columns,
/// into `out` (reused from line to line, so a line allocates nothing).
void tokenize(std::string_view line, std::vector<Token>& out) {
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
std::string_view first_word(std::string_view line) {
    const char* p = line.data();
    const char* const end = p + line.size();
    while (p < end && byte_class(*p) == kSpace) ++p;
    const char* start = p;
    while (p < end && byte_class(*p) == 0) ++p;
    return std::string_view(start, std::size_t(p - start));
}

/// A finite double written entirely in `s` (an optional leading '+' is accepted).
std::optional<double> to_number(std::string_view s) {
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
std::optional<glm::dvec3> to_vec3(std::string_view s) {
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

bool all_finite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

/// Not usable as Md: not finite, (nearly) singular, or with an inverse that overflows (a tiny
/// scale followed by a huge translation gives a finite Md whose Mi is not).
bool singular(const glm::dmat4& m) {
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
                std::string msg = "unknown key " + quote(a.key) + " for '" + std::string(word()) +
                                  "' (expected one of:";
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

// ---- key vocabularies ------------------------------------------------------------------
const std::vector<std::string_view> kMaterialKeys = {"color", "ambi",    "diff", "spec",
                                                     "shininess", "refl", "trans", "ior",
                                                     "checker", "cell", "fresnel",
                                                     "texture", "uvscale"};  // textures
const std::vector<std::string_view> kTransformKeys = {"scale", "rotate_x", "rotate_y", "rotate_z",
                                                      "translate"};
const std::vector<std::string_view> kImageKeys = {"width",  "height",  "spp",
                                                  "depth",  "degree",  "output",
                                                  "sampler", "calibration", "cutoff",
                                                  "colorspace", "exposure", "tonemap", "exr",
                                                  "frames"};
const std::vector<std::string_view> kLookAtKeys = {"eye", "look", "up", "fov"};
const std::vector<std::string_view> kExplicitCameraKeys = {"rx",       "ry",       "df",
                                                           "scale",    "rotate_x", "rotate_y",
                                                           "rotate_z", "translate"};
/// Depth of field: keys of both camera forms.
const std::vector<std::string_view> kLensKeys = {"aperture", "focus"};

std::vector<std::string_view> join(std::initializer_list<std::vector<std::string_view>> lists) {
    std::vector<std::string_view> out;
    for (const auto& l : lists) out.insert(out.end(), l.begin(), l.end());
    return out;
}

// The joined lists, built once (the order is the one messages list them in).
const std::vector<std::string_view> kCameraKeys = join({kLookAtKeys, kExplicitCameraKeys, kLensKeys, {"name"}});
const std::vector<std::string_view> kMaterialStatementKeys = join({kMaterialKeys, {"material"}});
const std::vector<std::string_view> kShapeKeys = join({{"material"}, kMaterialKeys, kTransformKeys, {"name"}});
const std::vector<std::string_view> kMeshKeys = join({kShapeKeys, {"file", "smooth", "materials"}});
const std::vector<std::string_view> kPointLightKeys = {"pos", "color", "falloff", "name"};
const std::vector<std::string_view> kSpotLightKeys = {"pos", "dir", "angle", "color", "falloff", "soft", "name"};
const std::vector<std::string_view> kDirectionalLightKeys = {"dir", "color", "falloff", "name"};
// Area lights (docs/scene-format.md, "Area lights and soft shadows").
const std::vector<std::string_view> kSphereLightKeys = {"pos", "radius", "color", "samples", "falloff", "name"};
const std::vector<std::string_view> kRectLightKeys = {"pos", "u", "v", "color", "samples", "falloff", "name"};
// The `key` statement's keys, by what the name names (animation, scene/animation.h).
const std::vector<std::string_view> kObjectKeyKeys = {"frame", "translate", "rotate", "scale"};
const std::vector<std::string_view> kLightKeyKeys = {"frame", "pos", "color"};
const std::vector<std::string_view> kCameraKeyKeys = {"frame", "eye", "look", "fov"};
const std::vector<std::string_view> kKeyKeys = join({kObjectKeyKeys, {"pos", "color", "eye", "look", "fov"}});

/// Each kind's keys: the common ones, plus its parameter key (shapes/shapes.h) or the mesh's.
const std::array<std::vector<std::string_view>, kShapeKindCount> kKeysOfKind = [] {
    std::array<std::vector<std::string_view>, kShapeKindCount> keys;
    for (int k = 0; k < kShapeKindCount; ++k) {
        const ShapeParam p = shape_param(ShapeKind(k));
        keys[std::size_t(k)] = p.present() ? join({kShapeKeys, {p.key}}) : kShapeKeys;
    }
    keys[std::size_t(ShapeKind::Mesh)] = kMeshKeys;
    return keys;
}();

const std::vector<std::string_view>& shape_keys(ShapeKind kind) { return kKeysOfKind[std::size_t(kind)]; }

bool contains(const std::vector<std::string_view>& v, std::string_view k) {
    return std::find(v.begin(), v.end(), k) != v.end();
}

/// What a `material` statement names and a shape's material keys set: the optical
/// parameters and the colour (stored apart in the scene: Object::color, Scene::materials).
struct Appearance {
    Material m;
    glm::dvec3 color{1.0, 1.0, 1.0};
};

/// Applies one material key; false when `a` is not a material key.
bool apply_material_key(const Statement& st, const Arg& a, Appearance& ap) {
    const auto k = a.key;
    Material& m = ap.m;
    if (same(k, "color")) ap.color = st.color(a);
    else if (same(k, "ambi")) m.ambi = st.at_least_zero(a);
    else if (same(k, "diff")) m.diff = st.at_least_zero(a);
    else if (same(k, "spec")) m.spec = st.at_least_zero(a);
    else if (same(k, "shininess")) m.shininess = st.at_least_zero(a);
    else if (same(k, "refl")) m.refl = st.at_least_zero(a);
    else if (same(k, "trans")) m.trans = st.at_least_zero(a);
    else if (same(k, "ior")) m.ior = st.positive(a);
    else if (same(k, "checker")) {
        m.checker_color = st.color(a);
        m.checker = true;
    } else if (same(k, "cell")) m.cell = st.positive(a);
    else if (same(k, "fresnel")) m.fresnel = st.boolean(a);
    else if (same(k, "uvscale")) m.uv_scale = st.positive(a);  // texture= is the Parser's (texture_file)
    else return false;
    return true;
}

/// Applies one transform key on the left of `md` (written order = application order).
bool apply_transform_key(const Statement& st, const Arg& a, glm::dmat4& md) {
    const auto k = a.key;
    glm::dmat4 t;
    // Scale and translate, the common keys, touch only what they change: the same values as
    // the full products S Md and T Md of an affine Md (the skipped terms are exact zeros).
    if (same(k, "scale")) {
        const glm::dvec3 s = st.scale(a);
        for (int c = 0; c < 4; ++c) md[c] *= glm::dvec4(s, 1.0);
        return true;
    }
    if (same(k, "translate")) {
        const glm::dvec3 v = st.vec3(a);
        for (int c = 0; c < 4; ++c) md[c] += glm::dvec4(v * md[c][3], 0.0);
        return true;
    }
    if (same(k, "rotate_x")) t = rotate_x_matrix(st.number(a));
    else if (same(k, "rotate_y")) t = rotate_y_matrix(st.number(a));
    else if (same(k, "rotate_z")) t = rotate_z_matrix(st.number(a));
    else return false;
    md = t * md;
    return true;
}

std::optional<ShapeKind> shape_from_word(std::string_view w) { return canonical_shape_named(w); }

/// The statement words, in the order the unknown-statement message lists them.
const std::string kStatementList = [] {
    std::string list = "image, ambient, background, camera, light, material, key, ";
    CanonicalShapes::for_each([&](auto s) { list += std::string(s.name) + ", "; });
    return list + "mesh or include";
}();

/// The statement words the chunked reader parses in parallel (mesh and include fall back to
/// one sequential pass: they read other files).
bool is_plain_shape(std::string_view w) { return shape_from_word(w).has_value(); }

/// A path's identity for cycle detection.
fs::path identity_of(const fs::path& p) {
    std::error_code ec;
    fs::path id = fs::weakly_canonical(p, ec);
    if (ec) {
        id = fs::absolute(p, ec);
        if (ec) id = p;
        id = id.lexically_normal();
    }
    return id;
}

/// A scene file's bytes: mapped read-only (the chunked reader gives parsed ranges back, see
/// advise_inside), or read into a string when mapping is not possible (an empty-looking file
/// such as those of /proc).
class FileText {
  public:
    FileText() = default;
    FileText(const FileText&) = delete;
    FileText& operator=(const FileText&) = delete;
    ~FileText() {
        if (map_) ::munmap(map_, size_);
    }

    bool open(const fs::path& p) {
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) return false;
        const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) return false;
        struct stat st{};
        bool ok = ::fstat(fd, &st) == 0;
        if (ok && st.st_size > 0) {
            void* m = ::mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
            if (m != MAP_FAILED) {
                map_ = m;
                size_ = std::size_t(st.st_size);
                ::madvise(map_, size_, MADV_SEQUENTIAL);
            }
        }
        if (ok && !map_) {
            char buf[1 << 16];
            for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
                if (n < 0) {
                    ok = false;
                    break;
                }
                owned_.append(buf, std::size_t(n));
            }
        }
        ::close(fd);
        return ok;
    }

    std::string_view text() const {
        return map_ ? std::string_view(static_cast<const char*>(map_), size_) : std::string_view(owned_);
    }
    bool mapped() const { return map_ != nullptr; }

  private:
    void* map_ = nullptr;
    std::size_t size_ = 0;
    std::string owned_;
};

/// Per-thread lexing scratch: the token and argument lists of the line being read.
struct Scratch {
    std::vector<Token> toks;
    std::vector<Arg> args;
};

/// A material and the first line it may be used from (0 when read in one pass: whatever is
/// defined is usable, as statements run in order).
struct MaterialDef {
    Appearance look;
    int from_line = 0;
};

/// Where a pass puts the materials of the objects it reads: the scene's own deduplicated list
/// (one pass), or a chunk's private list, merged into the scene's in chunk order afterwards
/// (so the scene's list is the same for every thread count).
class MaterialList {
  public:
    std::uint32_t intern(const Material& m) {
        if (scene_) return scene_->intern_material(m);
        const auto [it, added] = index_.try_emplace(m, std::uint32_t(list_.size()));
        if (added) list_.push_back(m);
        return it->second;
    }
    explicit MaterialList(Scene* scene = nullptr) : scene_(scene) {}
    const std::vector<Material>& local() const { return list_; }

  private:
    Scene* scene_;
    std::unordered_map<Material, std::uint32_t, MaterialHash> index_;
    std::vector<Material> list_;
};

/// One chunk of a large text: complete lines [begin, end).
struct Chunk {
    std::size_t begin = 0, end = 0;
    int first_line = 0;                  // line number of `begin`
    std::size_t first_object = 0;        // its first slot in scene.objects
    MaterialList materials;              // its objects' materials, indexed by them until merged
    std::size_t shapes = 0;              // shape statements in it
    int lines = 0;                       // '\n' in it
    std::vector<std::pair<std::size_t, int>> others;  // non-shape statements: offset, line in chunk
    bool sequential_only = false;        // holds include or mesh
    std::exception_ptr error;            // the first one in the chunk
    int error_line = INT_MAX;
    struct Name {
        std::string_view text;
        int line, column;
        std::size_t slot;
    };
    std::vector<Name> names;             // the name= of its shapes (animation), in order
};

class Parser {
  public:
    Scene scene;

    explicit Parser(const ReadOptions& options) : options_(options) {}

    /// Reads a top-level text: chunked and in parallel when it is large and plain, else in
    /// one pass. `mapped`: the text is a private file mapping whose pages may be released.
    void read_top(std::string_view text, const std::string& display, const fs::path& id, bool mapped) {
        if (text.size() >= options_.chunked_from && read_chunked(text, display, mapped)) return;
        read_text(text, display, id, 0);
    }

    /// Reads the text of one file. `display` names it in messages; `id` identifies it for
    /// cycle detection; includes are resolved against `display`'s directory.
    void read_text(std::string_view text, const std::string& display, const fs::path& id,
                   int depth) {
        ++files_;
        open_.push_back(id);
        if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
        int line_no = 0;
        std::size_t pos = 0;
        while (pos <= text.size()) {
            auto nl = text.find('\n', pos);
            if (nl == std::string_view::npos) nl = text.size();
            ++line_no;
            statement(text.substr(pos, nl - pos), display, line_no, depth, scratch_);
            pos = nl + 1;
        }
        open_.pop_back();
    }

  private:
    ReadOptions options_;
    bool chunked_ = false;  // materials carry the line they are defined at (see MaterialDef)
    Scratch scratch_;       // the sequential pass's
    std::map<std::string, MaterialDef, std::less<>> materials_;
    std::vector<fs::path> open_;  // the include chain being read
    // By file identity and whether its texture coordinates are kept: loaded once, shared
    // (index in scene.meshes).
    std::map<std::pair<fs::path, bool>, std::uint32_t> meshes_;
    MaterialList scene_materials_{&scene};  // the one-pass reader's: straight into the scene
    int files_ = 0;

    /// The chunked reader. First pass (parallel): cut into chunks at line ends, count lines
    /// and shape statements, note the other statements. Then the other statements run in
    /// file order, then the shapes of every chunk are parsed (parallel) into their own slice
    /// of scene.objects, reserved once. The first error in file order wins. False (nothing
    /// done) when the text holds include or mesh: those are read in one sequential pass.
    bool read_chunked(std::string_view text, const std::string& display, bool mapped) {
        if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
        std::vector<Chunk> chunks;
        const std::size_t step = std::max<std::size_t>(1, options_.chunk_bytes);
        for (std::size_t b = 0; b < text.size();) {
            std::size_t e = std::min(text.size(), b + step);
            if (e < text.size()) {
                const auto nl = text.find('\n', e - 1);
                const std::size_t probe = e - 1;
                e = nl == std::string_view::npos ? text.size() : nl + 1;
                // One fault may map a whole large folio of the page cache (up to 2 MiB here):
                // without this, the boundary probes alone left ~90% of a 100 MB file mapped.
                if (mapped) {
                    constexpr std::size_t kFolio = std::size_t(2) << 20;
                    advise_inside(text.data() + (probe > kFolio ? probe - kFolio : 0),
                                  text.data() + std::min(text.size(), e + kFolio), MADV_DONTNEED);
                }
            }
            chunks.emplace_back();
            chunks.back().begin = b;
            chunks.back().end = e;
            b = e;
        }
        Parallelism par(options_.jobs);
        par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
            survey(text, chunks[i]);
            if (mapped) advise_inside(text.data() + chunks[i].begin, text.data() + chunks[i].end, MADV_DONTNEED);
        });
        std::size_t objects = 0;
        int line = 1;
        bool sequential_only = false;
        for (Chunk& c : chunks) {
            sequential_only = sequential_only || c.sequential_only;
            c.first_line = line;
            c.first_object = objects;
            line += c.lines;
            objects += c.shapes;
        }
        if (sequential_only) {
            scene.objects.reserve(objects);  // this file's shapes at least: fewer regrowths
            return false;
        }
        chunked_ = true;
        ++files_;

        // The other statements, in file order; they stop at their first error. Their name=
        // (lights, camera) is recorded with the shapes' below, in file order.
        deferred_names_.clear();
        defer_names_ = true;
        std::exception_ptr other_error;
        int other_error_line = INT_MAX;
        for (const Chunk& c : chunks) {
            for (const auto& [offset, in_chunk] : c.others) {
                const int at = c.first_line + in_chunk;
                try {
                    statement(line_at(text, offset), display, at, 0, scratch_);
                } catch (...) {
                    other_error = std::current_exception();
                    other_error_line = at;
                    break;
                }
            }
            if (other_error) break;
        }
        defer_names_ = false;

        const std::uint32_t file = file_index(display);
        scene.objects.reserve(objects);
        Object* const slots = scene.objects.data();
        advise_inside(slots, slots + objects, MADV_HUGEPAGE, std::uintptr_t(2) << 20);
        par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
            advise_inside(slots + chunks[i].first_object, slots + chunks[i].first_object + chunks[i].shapes,
                          MADV_POPULATE_WRITE);
        });
        scene.objects.resize(objects);
        scene.object_locs.resize(objects);
        // Every chunk is read even after an error: which error comes first is then decided
        // below in file order, never by which thread got there first.
        par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
            read_shapes(text, display, file, chunks[i]);
            if (mapped) advise_inside(text.data() + chunks[i].begin, text.data() + chunks[i].end, MADV_DONTNEED);
        });
        // name= of every statement in file order, up to the first error (a bad or repeated name
        // before it is the first error, as in a one-pass read).
        int first_error_line = other_error_line;
        for (const Chunk& c : chunks)
            if (c.error) first_error_line = std::min(first_error_line, c.error_line);
        for (const Chunk& c : chunks)
            for (const Chunk::Name& n : c.names)
                deferred_names_.push_back({display, n.line, Arg{"name", n.column, n.text, n.column}, Named::Object,
                                           std::uint32_t(n.slot)});
        std::stable_sort(deferred_names_.begin(), deferred_names_.end(),
                         [](const DeferredName& a, const DeferredName& b) { return a.line < b.line; });
        for (const DeferredName& n : deferred_names_)
            if (n.line < first_error_line) name_thing(n.file, n.line, n.arg, n.what, n.index);
        for (const Chunk& c : chunks)
            if (c.error && c.error_line < other_error_line) std::rethrow_exception(c.error);
        if (other_error) std::rethrow_exception(other_error);
        deferred_names_.clear();
        // The chunks' materials into the scene's list in chunk order, then each object's
        // chunk-local index replaced by the scene's (skipped where they coincide).
        std::vector<std::vector<std::uint32_t>> remap(chunks.size());
        for (std::size_t i = 0; i < chunks.size(); ++i)
            for (const Material& m : chunks[i].materials.local()) remap[i].push_back(scene.intern_material(m));
        par.for_each_index(chunks.size(), 1, [&](std::size_t i) {
            const std::vector<std::uint32_t>& to = remap[i];
            bool identity = true;
            for (std::uint32_t k = 0; k < to.size(); ++k) identity = identity && to[k] == k;
            if (identity) return;
            for (std::size_t k = chunks[i].first_object; k < chunks[i].first_object + chunks[i].shapes; ++k)
                scene.objects[k].material = to[scene.objects[k].material];
        });
        return true;
    }

    static std::string_view line_at(std::string_view text, std::size_t offset) {
        const auto nl = text.find('\n', offset);
        return text.substr(offset, (nl == std::string_view::npos ? text.size() : nl) - offset);
    }

    /// First pass over a chunk: lines, shapes, the offsets of the other statements.
    static void survey(std::string_view text, Chunk& c) {
        for (std::size_t pos = c.begin; pos < c.end;) {
            const std::string_view line = line_at(text, pos);
            const std::string_view w = first_word(line);
            if (is_plain_shape(w)) ++c.shapes;
            else if (w == "include" || w == "mesh" || w == "key") c.sequential_only = true;
            else if (!w.empty()) c.others.emplace_back(pos, c.lines);
            pos += line.size() + 1;
            ++c.lines;
        }
    }

    /// Second pass over a chunk: its shapes into scene.objects[c.first_object...]; stops at
    /// the chunk's first error (kept with its line).
    void read_shapes(std::string_view text, const std::string& display, std::uint32_t file, Chunk& c) {
        Scratch scratch;
        std::size_t slot = c.first_object;
        int line_no = c.first_line;
        try {
            for (std::size_t pos = c.begin; pos < c.end; ++line_no) {
                const std::string_view line = line_at(text, pos);
                pos += line.size() + 1;
                tokenize(line, scratch.toks);
                if (scratch.toks.empty()) continue;
                const auto kind = shape_from_word(scratch.toks[0].text);
                if (!kind) continue;  // already read, in file order
                Statement st(display, line_no, scratch.toks[0], scratch.args);
                if (const auto name = shape(st, scratch.toks, *kind, file, c.materials, scene.objects[slot],
                                            scene.object_locs[slot]))
                    c.names.push_back({name->value, line_no, name->value_col, slot});
                ++slot;
            }
        } catch (...) {
            c.error = std::current_exception();
            c.error_line = line_no;
        }
    }

    void statement(std::string_view line, const std::string& file, int line_no, int depth, Scratch& scratch) {
        tokenize(line, scratch.toks);
        const std::vector<Token>& toks = scratch.toks;
        if (toks.empty()) return;
        Statement st(file, line_no, toks[0], scratch.args);
        const auto w = toks[0].text;
        if (w == "image") image(st, toks);
        else if (w == "ambient") ambient(st, toks);
        else if (w == "background") background(st, toks);
        else if (w == "camera") camera(st, toks);
        else if (w == "light") light(st, toks);
        else if (w == "material") material(st, toks);
        else if (w == "include") include(st, toks, depth);
        else if (w == "key") key(st, toks);
        else if (w == "mesh") one_pass_shape(st, toks, ShapeKind::Mesh);
        else if (auto kind = shape_from_word(w)) one_pass_shape(st, toks, *kind);
        else
            st.fail_here("unknown statement " + quote(w) + " (expected " + kStatementList + ")");
    }

    /// The single positional value of `ambient`, `background` and `include`.
    static const Token& single_value(const Statement& st, const std::vector<Token>& toks,
                                     std::string_view what) {
        if (toks.size() < 2)
            st.fail_here("expected " + std::string(what) + " after '" + std::string(st.word()) + "'");
        if (toks.size() > 2)
            st.fail(toks[2].column, "unexpected " + quote(toks[2].text) + " after the value of '" +
                                        std::string(st.word()) + "'");
        return toks[1];
    }

    void image(Statement& st, const std::vector<Token>& toks) {
        st.read_args(toks, 1, kImageKeys);
        RenderSettings& s = scene.settings;
        for (const Arg& a : st.args) {
            const auto k = a.key;
            if (k == "width") s.width = st.integer(a, 1, 32768);
            else if (k == "height") s.height = st.integer(a, 1, 32768);
            else if (k == "spp") s.spp = st.integer(a, 1, 65536);
            else if (k == "depth") s.depth = st.integer(a, 0, 256);
            else if (k == "degree") s.degree = st.integer(a, 0, 5);
            else if (k == "cutoff") s.cutoff = st.in_closed(a, 0.0, 1.0);
            else if (k == "output") s.output = std::string(a.value);
            else if (k == "frames") frame_range(st, a, s.frames_first, s.frames_last);
            else if (k == "sampler") {
                if (a.value == "stratified") s.pattern = SamplePattern::Stratified;
                else if (a.value == "grid") s.pattern = SamplePattern::Grid;
                else if (a.value == "random") s.pattern = SamplePattern::Random;
                else
                    st.fail(a.value_col, "expected stratified, grid or random for 'sampler', got " +
                                             quote(a.value));
            } else if (k == "calibration") {
                if (a.value == "clamp") s.calibration = Calibration::Clamp;
                else if (a.value == "normalize") s.calibration = Calibration::Normalize;
                else
                    st.fail(a.value_col,
                            "expected clamp or normalize for 'calibration', got " + quote(a.value));
            } else {
                display_key(st, a, s);
            }
        }
    }

    // The display colour keys of `image` (docs/scene-format.md, "Output and display colour").
    static void display_key(const Statement& st, const Arg& a, RenderSettings& s) {
        const auto k = a.key;
        if (k == "exposure") {
            // Bounded so that it stays a normal float factor for the 8-bit conversion.
            const double v = st.number(a);
            if (!(v >= 1e-6 && v <= 1e6))
                st.fail(a.value_col, "'exposure' must be a multiplier > 0, in [1e-6, 1e6], got " + quote(a.value));
            s.exposure = v;
        } else if (k == "colorspace") {
            if (a.value == "srgb") s.colorspace = ColorSpace::Srgb;
            else if (a.value == "linear") s.colorspace = ColorSpace::Linear;
            else st.fail(a.value_col, "expected srgb or linear for 'colorspace', got " + quote(a.value));
        } else if (k == "tonemap") {
            if (a.value == "clamp") s.tonemap = Tonemap::Clamp;
            else if (a.value == "reinhard") s.tonemap = Tonemap::Reinhard;
            else st.fail(a.value_col, "expected clamp or reinhard for 'tonemap', got " + quote(a.value));
        } else if (k == "exr") {
            if (a.value == "half") s.exr = ExrPixels::Half;
            else if (a.value == "float") s.exr = ExrPixels::Float;
            else st.fail(a.value_col, "expected half or float for 'exr', got " + quote(a.value));
        }
    }

    void ambient(Statement& st, const std::vector<Token>& toks) {
        const Token& t = single_value(st, toks, "a number in [0, 1]");
        const Arg a{"ambient", t.column, t.text, t.column};
        scene.settings.ambient = st.in_closed(a, 0.0, 1.0);
    }

    void background(Statement& st, const std::vector<Token>& toks) {
        const Token& t = single_value(st, toks, "a colour r,g,b");
        const Arg a{"background", t.column, t.text, t.column};
        scene.settings.background = st.color(a);
    }

    void camera(Statement& st, const std::vector<Token>& toks) {
        st.read_args(toks, 1, kCameraKeys);
        Camera cam;
        // The lens keys and name= belong to both forms; the first other key chooses the form.
        const auto either_form = [](const Arg& a) { return same(a.key, "name") || contains(kLensKeys, a.key); };
        if (const auto placing = std::find_if_not(st.args.begin(), st.args.end(), either_form);
            placing != st.args.end()) {
            const Arg& first = *placing;
            const bool look_at = contains(kLookAtKeys, first.key);
            for (const Arg& a : st.args)
                if (!either_form(a) && contains(kLookAtKeys, a.key) != look_at)
                    st.fail(a.key_col, "camera: " + quote(a.key) + " belongs to the " +
                                           (look_at ? "explicit" : "look-at") + " form but " +
                                           quote(first.key) + " chose the " +
                                           (look_at ? "look-at" : "explicit") +
                                           " form; use one form per camera statement");
            cam.look_at = look_at;
        }
        for (const Arg& a : st.args) {  // depth of field (the stream engine's lens is float)
            if (a.key != "aperture" && a.key != "focus") continue;
            const double v = a.key == "aperture" ? st.at_least_zero(a) : st.positive(a);
            if (!(v <= double(std::numeric_limits<float>::max())))
                st.fail(a.value_col, quote(a.key) + " must be at most 3.4e38 (single precision), got " + quote(a.value));
            (a.key == "aperture" ? cam.aperture : cam.focus) = v;
        }
        if (cam.look_at) {
            const Arg* up = nullptr;
            for (const Arg& a : st.args) {
                if (a.key == "eye") cam.eye = st.vec3(a);
                else if (a.key == "look") cam.look = st.vec3(a);
                else if (a.key == "up") {
                    cam.up = st.direction(a);
                    up = &a;
                } else if (a.key == "fov") cam.fov = st.in_open(a, 0.0, 180.0);
            }
            const glm::dvec3 fwd = cam.look - cam.eye;
            if (!(glm::length(fwd) > 0.0) || !std::isfinite(glm::length(fwd)))
                st.fail_here("camera: 'eye' and 'look' must be distinct points");
            const double side = glm::length(glm::cross(glm::normalize(fwd), cam.up));
            if (!(side > 1e-9)) {
                const std::string msg = "camera: 'up' must not be parallel to the view direction";
                if (up) st.fail(up->value_col, msg);
                st.fail_here(msg);
            }
            // The conversion happens once the image size is known; check it is invertible.
            if (singular(cam.world_from_canonical(1, 1)))
                st.fail_here("camera: the look-at placement gives a singular transform");
        } else {
            double rx = 1.0, ry = 1.0, df = 1.0;
            glm::dmat4 xf(1.0);
            for (const Arg& a : st.args) {
                if (a.key == "rx") rx = st.positive(a);
                else if (a.key == "ry") ry = st.positive(a);
                else if (a.key == "df") df = st.positive(a);
                else apply_transform_key(st, a, xf);
            }
            cam.md = xf * scale_matrix({rx, ry, df});
            if (singular(cam.md)) st.fail_here("camera: the composed transform is singular");
        }
        scene.camera = cam;
        if (const Arg* n = st.find("name")) name_thing(st.file(), st.line(), *n, Named::Camera, 0);
    }

    void light(Statement& st, const std::vector<Token>& toks) {
        if (toks.size() < 2)
            st.fail_here("expected a light kind (point, spot, directional, sphere or rect) after 'light'");
        const Token& kt = toks[1];
        Light l;
        const std::vector<std::string_view>* keys = nullptr;
        if (kt.text == "point") {
            l.kind = LightKind::Point;
            keys = &kPointLightKeys;
        } else if (kt.text == "spot") {
            l.kind = LightKind::Spot;
            keys = &kSpotLightKeys;
        } else if (kt.text == "directional") {
            l.kind = LightKind::Directional;
            keys = &kDirectionalLightKeys;
        } else if (kt.text == "sphere") {
            l.kind = LightKind::Sphere;
            keys = &kSphereLightKeys;
        } else if (kt.text == "rect") {
            l.kind = LightKind::Rect;
            keys = &kRectLightKeys;
        } else {
            st.fail(kt.column,
                    "expected a light kind (point, spot, directional, sphere or rect), got " + quote(kt.text));
        }
        st.read_args(toks, 2, *keys);
        for (const Arg& a : st.args) {
            if (a.key == "pos") l.pos = st.vec3(a);
            else if (a.key == "dir") l.dir = st.direction(a);
            else if (a.key == "angle") l.angle = st.in_open(a, 0.0, 180.0);
            else if (a.key == "color") l.color = st.color(a);
            else area_light_key(st, a, l);
        }
        const bool needs_pos = l.kind != LightKind::Directional;
        const bool needs_dir = l.kind == LightKind::Spot || l.kind == LightKind::Directional;
        const std::string kind(kt.text);
        if (needs_pos && !st.find("pos")) st.fail_here("light " + kind + " needs 'pos=x,y,z'");
        if (needs_dir && !st.find("dir")) st.fail_here("light " + kind + " needs 'dir=x,y,z'");
        check_area_light(st, l);
        scene.lights.push_back(l);
        if (const Arg* n = st.find("name"))
            name_thing(st.file(), st.line(), *n, Named::Light, std::uint32_t(scene.lights.size() - 1));
    }

    /// The keys of area lights, falloff and soft spot edges.
    static void area_light_key(const Statement& st, const Arg& a, Light& l) {
        if (a.key == "radius") l.radius = st.positive(a);
        else if (a.key == "u") l.u = st.vec3(a);
        else if (a.key == "v") l.v = st.vec3(a);
        else if (a.key == "samples") l.samples = st.integer(a, 1, 4096);
        else if (a.key == "soft") l.soft = st.at_least_zero(a);
        else if (a.key == "falloff") {
            if (a.value == "none") l.falloff = Falloff::None;
            else if (a.value == "inverse_square") l.falloff = Falloff::InverseSquare;
            else st.fail(a.value_col, "expected none or inverse_square for 'falloff', got " + quote(a.value));
        }
    }

    /// What an area light or a soft edge needs beyond its keys' own ranges.
    static void check_area_light(const Statement& st, const Light& l) {
        if (l.kind == LightKind::Sphere && !st.find("radius")) st.fail_here("light sphere needs 'radius=r'");
        if (l.kind == LightKind::Rect) {
            if (!st.find("u")) st.fail_here("light rect needs 'u=x,y,z'");
            if (!st.find("v")) st.fail_here("light rect needs 'v=x,y,z'");
            const double area = glm::length(glm::cross(l.u, l.v));
            // Relative to the edges' lengths, so the test does not depend on the scene's unit.
            if (!(area > 1e-12 * glm::length(l.u) * glm::length(l.v)) || !std::isfinite(area))
                st.fail(st.find("v")->value_col, "light rect: 'u' and 'v' span no area (u x v = 0)");
        }
        if (const Arg* s = st.find("soft"); s && !(l.soft < l.angle))
            st.fail(s->value_col, "'soft' must be below the spot's 'angle' (" + fmt_num(l.angle) + "), got " +
                                      quote(s->value));
    }

    /// The material named by `a`, as defined at this statement: the chunked reader has read
    /// every material statement first, so one defined on a later line is refused here.
    const Appearance& lookup_material(const Statement& st, const Arg& a) const {
        const auto it = materials_.find(a.value);
        if (it == materials_.end() || it->second.from_line > st.line())
            st.fail(a.value_col, "unknown material " + quote(a.value) +
                                     " (a material must be defined before it is used)");
        return it->second.look;
    }

    void material(Statement& st, const std::vector<Token>& toks) {
        if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
            st.fail(toks.size() < 2 ? toks[0].column : toks[1].column,
                    "expected a material name after 'material'");
        const Token& name = toks[1];
        if (const auto it = materials_.find(name.text); it != materials_.end())
            st.fail(name.column, "material " + quote(name.text) + " is already defined");
        st.read_args(toks, 2, kMaterialStatementKeys);  // "material": a base to start from
        Appearance m;
        if (const Arg* base = st.find("material")) m = lookup_material(st, *base);
        for (const Arg& a : st.args)
            if (same(a.key, "texture")) m.m.texture = texture_file(st, a);
            else apply_material_key(st, a, m);
        materials_.emplace(std::string(name.text), MaterialDef{m, chunked_ ? st.line() : 0});
    }

    /// What a shape statement says, before it becomes an Object (make_object).
    struct ShapeFields {
        ShapeKind kind = ShapeKind::Sphere;
        Appearance look;
        glm::dmat4 md{1.0};
        double param = 0.0;  // the shape's parameter (ShapeParam: the torus's minor)
        bool smooth = false;
        std::optional<std::uint32_t> mesh;  // index in scene.meshes
    };

    /// The one place an Object is built from a checked shape statement, in place: `obj` and
    /// `loc` are its slots in scene.objects and scene.object_locs.
    static void make_object(const Statement& st, const ShapeFields& f, std::uint32_t file, MaterialList& materials,
                            Object& obj, ObjectLoc& loc) {
        obj.kind = f.kind;
        obj.md = glm::dmat4x3(f.md);
        obj.param = f.kind == ShapeKind::Mesh ? (f.smooth ? 1.0 : 0.0) : f.param;
        obj.color = glm::vec3(f.look.color);
        obj.material = materials.intern(f.look.m);
        obj.mesh = f.mesh.value_or(0);
        loc = ObjectLoc{file, st.line(), st.where().column};
    }

    /// A shape statement of the one-pass reader, appended to the scene.
    void one_pass_shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind) {
        const std::uint32_t file = file_index(st.file());
        Object obj;
        ObjectLoc loc;
        const std::optional<Arg> name = shape(st, toks, kind, file, scene_materials_, obj, loc);
        if (name) name_thing(st.file(), st.line(), *name, Named::Object, std::uint32_t(scene.objects.size()));
        scene.objects.push_back(obj);
        scene.object_locs.push_back(loc);
        for (const auto& [o, l] : extra_objects_) {  // materials=obj: the file's other parts
            scene.objects.push_back(o);
            scene.object_locs.push_back(l);
        }
        extra_objects_.clear();
    }

    /// The index of a file name in Scene::files (one-pass reader and set-up only: not
    /// thread-safe).
    std::uint32_t file_index(const std::string& file) {
        if (!scene.files.empty() && scene.files[last_file_] == file) return last_file_;
        for (std::uint32_t i = 0; i < scene.files.size(); ++i)
            if (scene.files[i] == file) return last_file_ = i;
        scene.files.push_back(file);
        return last_file_ = std::uint32_t(scene.files.size() - 1);
    }
    std::uint32_t last_file_ = 0;

    /// Reads a shape statement into `out` and `loc`; its `name=` argument, if any.
    std::optional<Arg> shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind, std::uint32_t file,
                             MaterialList& materials, Object& out, ObjectLoc& loc) {
        st.read_args(toks, 1, shape_keys(kind));
        ShapeFields f;
        f.kind = kind;
        const ShapeParam param = shape_param(kind);
        f.param = param.default_value;
        if (const Arg* base = st.find("material")) f.look = lookup_material(st, *base);
        const Arg* file_arg = nullptr;  // a mesh's file, read once the texture is known
        bool obj_materials = false;     // materials=obj: the file's own materials, a part each
        for (const Arg& a : st.args) {
            if (same(a.key, "material") || same(a.key, "name")) continue;
            if (same(a.key, "texture")) {
                f.look.m.texture = texture_file(st, a);
                continue;
            }
            if (apply_material_key(st, a, f.look)) continue;
            if (apply_transform_key(st, a, f.md)) continue;
            if (param.present() && same(a.key, param.key)) f.param = st.positive(a);
            else if (same(a.key, "smooth")) f.smooth = st.boolean(a);
            else if (same(a.key, "file")) {
                file_arg = &a;
            } else if (same(a.key, "materials")) {
                if (!same(a.value, "obj"))
                    st.fail(a.value_col, "expected obj for 'materials' (the OBJ file's own materials), got " +
                                             quote(a.value));
                obj_materials = true;
            }
        }
        if (file_arg && obj_materials) {
            if (singular(f.md))
                st.fail_here(std::string(st.word()) + ": the composed transform is singular (or not finite)");
            // One object per part (usemtl group), each with its part's material over the
            // statement's; the first goes into `out`, the others after it (one-pass reader only:
            // mesh statements are never read in chunks).
            const ObjParts& parts = obj_parts(st, *file_arg, f.look.m.texture >= 0);
            for (std::size_t k = 0; k < parts.meshes.size(); ++k) {
                ShapeFields g = f;
                g.mesh = parts.meshes[k];
                apply_obj_material(st, *file_arg, parts, parts.materials[k], g.look);
                if (k == 0) {
                    make_object(st, g, file, materials, out, loc);
                } else {
                    extra_objects_.emplace_back();
                    make_object(st, g, file, materials, extra_objects_.back().first, extra_objects_.back().second);
                }
            }
            if (const Arg* n = st.find("name")) return *n;
            return std::nullopt;
        }
        if (file_arg) f.mesh = mesh_file(st, *file_arg, f.look.m.texture >= 0);
        if (kind == ShapeKind::Mesh && !f.mesh) st.fail_here("mesh needs 'file=PATH' (a Wavefront OBJ file)");
        if (singular(f.md))
            st.fail_here(std::string(st.word()) +
                         ": the composed transform is singular (or not finite)");
        make_object(st, f, file, materials, out, loc);
        if (const Arg* n = st.find("name")) return *n;
        return std::nullopt;
    }

    /// The file `a` names, relative to the statement's file.
    static fs::path target_of(const Statement& st, const Arg& a) {
        return (fs::path(st.file()).parent_path() / fs::path(std::string(a.value))).lexically_normal();
    }

    /// A file read once: its index in `list`, remembered in `known` under key(its identity);
    /// load(path) reads it the first time. Errors at column `col` of the statement.
    template <class Map, class List, class Key, class Load>
    typename Map::mapped_type read_once(const Statement& st, int col, const fs::path& target, const std::string& what,
                                        Map& known, List& list, Key key, Load load) {
        const auto id = key(identity_of(target));
        if (const auto it = known.find(id); it != known.end()) return it->second;
        std::error_code ec;
        if (!fs::is_regular_file(target, ec)) st.fail(col, "cannot open " + what + " file " + quote(target.string()));
        if (options_.copies) copy_file(target);
        try {
            auto item = load(target.string());
            const auto index = typename Map::mapped_type(list.size());
            list.push_back(std::move(item));
            known.emplace(id, index);
            return index;
        } catch (const std::exception& e) {
            st.fail(col, quote(target.string()) + ": " + e.what());
        }
    }

    /// The mesh of an OBJ file, read once per file (twice when both untextured objects and
    /// textured ones, which need its texture coordinates, use it): its index in Scene::meshes.
    std::uint32_t mesh_file(const Statement& st, const Arg& a, bool with_uv) {
        return read_once(
            st, a.value_col, target_of(st, a), "mesh", meshes_, scene.meshes,
            [&](fs::path id) { return std::pair{std::move(id), with_uv}; },
            [&](const std::string& path) { return load_obj_mesh(path, with_uv); });
    }

    /// The texture of an image file, read once per file: its index in Scene::textures.
    /// Shapes of the chunked reader call it from several threads, hence the lock.
    std::int32_t texture_file(const Statement& st, int col, const fs::path& target) {
        std::lock_guard<std::mutex> lock(textures_mutex_);
        return read_once(
            st, col, target, "texture", textures_, scene.textures, [](fs::path id) { return id; },
            [](const std::string& path) { return load_texture(path); });
    }
    std::int32_t texture_file(const Statement& st, const Arg& a) { return texture_file(st, a.value_col, target_of(st, a)); }

    /// An OBJ file read with its materials (mesh materials=obj): once per file and need of
    /// texture coordinates; its parts' meshes are in Scene::meshes.
    struct ObjParts {
        std::vector<std::uint32_t> meshes;  ///< per part, index in Scene::meshes
        std::vector<int> materials;         ///< per part, index in `library` (-1: none)
        std::vector<ObjMaterial> library;
        std::string mtl_path;
    };
    const ObjParts& obj_parts(const Statement& st, const Arg& a, bool with_uv) {
        const std::size_t i = read_once(
            st, a.value_col, target_of(st, a), "mesh", obj_models_, obj_parts_,
            [&](fs::path id) { return std::pair{std::move(id), with_uv}; },
            [&](const std::string& path) {
                ObjModel model = load_obj_model(path, with_uv);
                ObjParts parts;
                for (ObjModel::Part& p : model.parts) {
                    parts.meshes.push_back(std::uint32_t(scene.meshes.size()));
                    scene.meshes.push_back(std::move(p.mesh));
                    parts.materials.push_back(p.material);
                }
                parts.library = std::move(model.materials);
                parts.mtl_path = model.mtl_path;
                if (options_.copies && !parts.mtl_path.empty()) copy_file(parts.mtl_path);
                return parts;
            });
        return obj_parts_[i];
    }
    std::map<std::pair<fs::path, bool>, std::size_t> obj_models_;
    std::vector<std::pair<Object, ObjectLoc>> extra_objects_;  // a materials=obj statement's parts after the first
    std::vector<ObjParts> obj_parts_;

    /// The material keys an OBJ material sets (docs/scene-format.md, "OBJ materials"), over
    /// the statement's appearance; map_Kd is read relative to the library's folder.
    void apply_obj_material(const Statement& st, const Arg& file, const ObjParts& parts, int material,
                            Appearance& look) {
        if (material < 0) return;
        const ObjMaterial& o = parts.library[std::size_t(material)];
        look.color = {o.kd[0], o.kd[1], o.kd[2]};
        look.m.spec = std::max(0.0, (o.ks[0] + o.ks[1] + o.ks[2]) / 3.0);
        look.m.shininess = std::max(0.0, o.ns);
        look.m.ior = o.ni > 0.0 ? o.ni : 1.0;
        look.m.trans = std::clamp(1.0 - o.d, 0.0, 1.0);
        if (!o.map_kd.empty())
            look.m.texture = texture_file(
                st, file.value_col, (fs::path(parts.mtl_path).parent_path() / fs::path(o.map_kd)).lexically_normal());
    }
    std::mutex textures_mutex_;
    std::map<fs::path, std::int32_t> textures_;  // by file identity (index in scene.textures)

    void copy_file(const fs::path& p) {
        FileText text;
        options_.copies->push_back(FileCopy{p.string(), text.open(p) ? std::string(text.text()) : std::string()});
    }

    void include(Statement& st, const std::vector<Token>& toks, int depth) {
        const Token& t = single_value(st, toks, "a file path");
        // A NUL would make the file opened differ from the file named (the OS stops at it);
        // no control byte belongs in a path here.
        for (const char c : t.text)
            if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
                st.fail(t.column, "include path " + quote(t.text) + " contains a control byte");
        const fs::path base = fs::path(st.file()).parent_path();
        const fs::path target = (base / fs::path(std::string(t.text))).lexically_normal();
        const std::string shown = target.string();
        if (depth + 1 > kMaxIncludeDepth)
            st.fail(t.column, "includes nested deeper than " + std::to_string(kMaxIncludeDepth) +
                                  " levels at " + quote(shown));
        if (files_ + 1 > kMaxFiles)
            st.fail(t.column, "more than " + std::to_string(kMaxFiles) +
                                  " files read through include at " + quote(shown));
        const fs::path id = identity_of(target);
        if (std::find(open_.begin(), open_.end(), id) != open_.end())
            st.fail(t.column, "include cycle: " + quote(shown) + " is already being read");
        FileText text;
        if (!text.open(target)) st.fail(t.column, "cannot open included file " + quote(shown));
        if (options_.copies) options_.copies->push_back(FileCopy{shown, std::string(text.text())});
        read_text(text.text(), shown, id, depth + 1);
    }

    // ---- animation: name= and the key statement (docs/scene-format.md, "Animation") ------
    enum class Named : std::uint8_t { Object, Light, Camera };
    struct NameDef {
        Named what;
        std::uint32_t index;  // in scene.objects or scene.lights
        int line;
    };
    std::map<std::string, NameDef, std::less<>> names_;  // one namespace for objects, lights, camera
    /// A chunked read records the names of all statements first and checks them in file order.
    struct DeferredName {
        std::string file;
        int line;
        Arg arg;
        Named what;
        std::uint32_t index;
    };
    std::vector<DeferredName> deferred_names_;
    bool defer_names_ = false;
    std::map<std::pair<std::string, int>, int> key_lines_;  // (name, frame) -> line of its key
    std::unordered_map<std::uint32_t, std::size_t> object_tracks_, light_tracks_;  // index -> track

    static const char* named_word(Named w) {
        return w == Named::Object ? "object" : w == Named::Light ? "light" : "camera";
    }

    /// Records `name=` of a statement at file:line; names are unique across objects, lights
    /// and the camera.
    void name_thing(const std::string& file, int line, const Arg& a, Named what, std::uint32_t index) {
        if (defer_names_) {
            deferred_names_.push_back({file, line, a, what, index});
            return;
        }
        const auto fail = [&](std::string_view msg) { throw SceneError(SourceLoc{file, line, a.value_col}, msg); };
        const std::string_view n = a.value;
        const auto word_char = [](char c) {
            return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                   c == '-' || c == '.';
        };
        if (!(std::isalpha(static_cast<unsigned char>(n[0])) || n[0] == '_') ||
            !std::all_of(n.begin(), n.end(), word_char) || n.size() > 64)
            fail("a name starts with a letter or '_' and holds letters, digits, '_', '-' or '.' (at most 64), got " +
                 quote(n));
        if (const auto it = names_.find(n); it != names_.end())
            fail("name " + quote(n) + " is already given to the " + named_word(it->second.what) + " of line " +
                 std::to_string(it->second.line));
        names_.emplace(std::string(n), NameDef{what, index, line});
    }

    Animation& animation() {
        if (!scene.animation) scene.animation = std::make_shared<Animation>();
        return *scene.animation;
    }

    /// key NAME frame=F k=v...: one key at frame F for each quantity given.
    void key(Statement& st, const std::vector<Token>& toks) {
        if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
            st.fail(toks.size() < 2 ? toks[0].column : toks[1].column,
                    "expected a name after 'key' (given with name= on an object, a light or the camera)");
        const Token& nt = toks[1];
        const auto it = names_.find(nt.text);
        if (it == names_.end())
            st.fail(nt.column, "key for an unknown name " + quote(nt.text) +
                                   " (name= on an object, light or camera before this line)");
        const NameDef& def = it->second;
        st.read_args(toks, 2, kKeyKeys);
        const std::vector<std::string_view>& fits = def.what == Named::Object  ? kObjectKeyKeys
                                                    : def.what == Named::Light ? kLightKeyKeys
                                                                               : kCameraKeyKeys;
        const std::string who = std::string(named_word(def.what)) + " " + quote(nt.text);
        for (const Arg& a : st.args)
            if (!contains(fits, a.key)) {
                std::string msg = "key: " + quote(a.key) + " does not fit the " + who + " (expected one of:";
                for (auto k : fits) (msg += ' ') += k;
                st.fail(a.key_col, msg + ")");
            }
        const Arg* fa = st.find("frame");
        if (!fa) st.fail_here("key needs 'frame=F' (an integer >= 0)");
        const int frame = st.integer(*fa, 0, kMaxFrame);
        if (st.args.size() < 2) st.fail_here("key: nothing keyed at frame " + std::to_string(frame) + " for " + who);
        const auto [seen, added] = key_lines_.try_emplace({std::string(nt.text), frame}, st.line());
        if (!added)
            st.fail(fa->value_col, who + " already has a key at frame " + std::to_string(frame) + " (line " +
                                       std::to_string(seen->second) + ")");
        Animation& anim = animation();
        if (def.what == Named::Object) {
            const auto [t, fresh] = object_tracks_.try_emplace(def.index, anim.objects.size());
            if (fresh) {
                anim.objects.emplace_back();
                anim.objects.back().object = def.index;
                anim.objects.back().base = scene.objects[def.index].md;
            }
            ObjectTrack& tr = anim.objects[t->second];
            for (const Arg& a : st.args) {
                if (same(a.key, "translate")) tr.translate.add(frame, st.vec3(a));
                else if (same(a.key, "scale")) {
                    const glm::dvec3 sc = st.scale(a);
                    if (!(sc.x > 0 && sc.y > 0 && sc.z > 0))
                        st.fail(a.value_col, "a keyed scale must be > 0 in every component, got " + quote(a.value));
                    tr.scale.add(frame, sc);
                } else if (same(a.key, "rotate")) tr.rotate.add(frame, rotation(st, a));
            }
            // Md at every key of the object stays usable (interpolation stays between them).
            for (const auto* track : {&tr.translate.frames, &tr.scale.frames, &tr.rotate.frames})
                for (const int f : *track)
                    if (singular(keyed_transform(tr, f) * glm::dmat4(tr.base)))
                        st.fail_here("key: the " + who + "'s transform at frame " + std::to_string(f) +
                                     " is singular or not finite");
        } else if (def.what == Named::Light) {
            const auto [t, fresh] = light_tracks_.try_emplace(def.index, anim.lights.size());
            if (fresh) {
                anim.lights.emplace_back();
                anim.lights.back().light = def.index;
            }
            LightTrack& tr = anim.lights[t->second];
            for (const Arg& a : st.args) {
                if (same(a.key, "pos")) {
                    if (scene.lights[def.index].kind == LightKind::Directional)
                        st.fail(a.key_col, "key: the " + who + " is directional: it has no 'pos'");
                    tr.pos.add(frame, st.vec3(a));
                } else if (same(a.key, "color")) tr.color.add(frame, st.color(a));
            }
        } else {
            if (!scene.camera.look_at)
                st.fail(nt.column, "key: the " + who + " has the explicit form; keys need the look-at form (eye=, look=)");
            CameraTrack& tr = anim.camera;
            for (const Arg& a : st.args) {
                if (same(a.key, "eye")) tr.eye.add(frame, st.vec3(a));
                else if (same(a.key, "look")) tr.look.add(frame, st.vec3(a));
                else if (same(a.key, "fov")) tr.fov.add(frame, st.in_open(a, 0.0, 180.0));
            }
            // The camera at this key's frame passes the camera statement's checks.
            Camera c = scene.camera;
            if (!tr.eye.empty()) c.eye = sample(tr.eye, frame);
            if (!tr.look.empty()) c.look = sample(tr.look, frame);
            if (!tr.fov.empty()) c.fov = sample(tr.fov, frame);
            const glm::dvec3 fwd = c.look - c.eye;
            if (!(glm::length(fwd) > 0.0) || !std::isfinite(glm::length(fwd)) ||
                !(glm::length(glm::cross(glm::normalize(fwd), c.up)) > 1e-9) ||
                singular(c.world_from_canonical(1, 1)))
                st.fail_here("key: at frame " + std::to_string(frame) +
                             " the camera's eye and look coincide, or the view is parallel to 'up'");
            camera_key_ = st.where();
        }
    }
    SourceLoc camera_key_;  // the last camera key, for an interpolated camera that degenerates

    /// rotate=ax,ay,az,degrees: a rotation about a non-zero axis, as a unit quaternion.
    static glm::dquat rotation(const Statement& st, const Arg& a) {
        const auto comma = a.value.rfind(',');
        const auto axis = comma == std::string_view::npos ? std::nullopt : to_vec3(a.value.substr(0, comma));
        const auto deg = comma == std::string_view::npos ? std::nullopt : to_number(a.value.substr(comma + 1));
        if (!axis || !deg)
            st.fail(a.value_col, "expected an axis and an angle ax,ay,az,degrees for 'rotate', got " + quote(a.value));
        const double len = glm::length(*axis);
        if (!(len > 0.0) || !std::isfinite(len))
            st.fail(a.value_col, "the axis of 'rotate' must be a non-zero vector, got " + quote(a.value));
        return glm::angleAxis(*deg * (3.14159265358979323846 / 180.0), *axis / len);
    }

    /// image frames=A..B.
    static void frame_range(const Statement& st, const Arg& a, int& first, int& last) {
        std::string why;
        if (!parse_frame_range(a.value, first, last, why)) st.fail(a.value_col, "'frames': " + why);
    }

  public:
    /// After the whole text: the scene is put at frame 0 (a still picture of an animated
    /// scene is frame 0).
    void finish() {
        if (!scene.animation) return;
        try {
            set_frame(scene, 0);
        } catch (const UsageError& e) {
            throw SceneError(camera_key_, e.what());
        }
    }
};

}  // namespace

Scene load_scene(const std::string& path, const ReadOptions& options) {
    FileText text;
    if (!text.open(fs::path(path))) throw SceneError(SourceLoc{path, 0, 0}, "cannot open scene file");
    if (options.copies) options.copies->push_back(FileCopy{path, std::string(text.text())});
    // Everything reading starts (meshes, their hierarchies) runs in options.jobs threads.
    return Parallelism(options.jobs).run([&] {
        Parser p(options);
        p.scene.path = path;
        p.read_top(text.text(), path, identity_of(path), text.mapped());
        p.finish();
        return std::move(p.scene);
    });
}

Scene load_scene(const std::string& path, int jobs) {
    ReadOptions options;
    options.jobs = jobs;
    return load_scene(path, options);
}

Scene parse_scene(std::string_view text, const std::string& name, const ReadOptions& options) {
    return Parallelism(options.jobs).run([&] {
        Parser p(options);
        p.scene.path = name;
        p.read_top(text, name, identity_of(name.empty() ? fs::path("<memory>") : fs::path(name)), false);
        p.finish();
        return std::move(p.scene);
    });
}

Scene parse_scene(std::string_view text, const std::string& name) { return parse_scene(text, name, ReadOptions{}); }

}  // namespace streamrt
