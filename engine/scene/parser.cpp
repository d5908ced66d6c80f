// The .cfg scene reader (docs/scene-format.md). One statement per line, `#` comments,
// `key=value` arguments; every mistake becomes a SceneError at the exact line and column of
// the offending token (the key, the value or the statement word).
#include "scene/parser.h"

#include "mesh/mesh.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
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

/// 's' for messages: at most 60 bytes, control bytes written as \xNN so that a message is
/// always one printable line.
std::string quote(std::string_view s) {
    constexpr std::size_t kMax = 60;
    std::string out = "'";
    for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (c < 0x20 || c == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += char(c);
        }
    }
    if (s.size() > kMax) out += "...";
    out += '\'';
    return out;
}

std::string fmt_num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Splits one line (comment removed) into whitespace-separated tokens with their columns.
std::vector<Token> tokenize(std::string_view line) {
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    std::vector<Token> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_space(line[i])) ++i;
        if (i >= line.size()) break;
        const std::size_t start = i;
        while (i < line.size() && !is_space(line[i])) ++i;
        out.push_back({line.substr(start, i - start), int(start) + 1});
    }
    return out;
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

/// Splits "a,b,c" into its components; empty components are kept (and rejected later).
std::vector<std::string_view> split_commas(std::string_view s) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    for (;;) {
        const auto comma = s.find(',', start);
        if (comma == std::string_view::npos) {
            parts.push_back(s.substr(start));
            return parts;
        }
        parts.push_back(s.substr(start, comma - start));
        start = comma + 1;
    }
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
class Statement {
  public:
    Statement(const std::string& file, int line, Token word) : file_(file), line_(line), word_(word) {}

    [[noreturn]] void fail(int column, std::string_view msg) const {
        throw SceneError(SourceLoc{file_, line_, column}, msg);
    }
    [[noreturn]] void fail_here(std::string_view msg) const { fail(word_.column, msg); }
    SourceLoc where() const { return SourceLoc{file_, line_, word_.column}; }
    std::string_view word() const { return word_.text; }
    const std::string& file() const { return file_; }
    int line() const { return line_; }

    std::vector<Arg> args;

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
            if (std::find(allowed.begin(), allowed.end(), a.key) == allowed.end()) {
                std::string msg = "unknown key " + quote(a.key) + " for '" + std::string(word()) +
                                  "' (expected one of:";
                for (auto k : allowed) msg += " " + std::string(k);
                msg += ")";
                fail(a.key_col, msg);
            }
            for (const Arg& prev : args)
                if (prev.key == a.key)
                    fail(a.key_col, "duplicate key " + quote(a.key) + " (first given at column " +
                                        std::to_string(prev.key_col) + ")");
            if (a.value.empty()) fail(a.value_col, "empty value for " + quote(a.key));
            args.push_back(a);
        }
    }

    const Arg* find(std::string_view key) const {
        for (const Arg& a : args)
            if (a.key == key) return &a;
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
        const auto parts = split_commas(a.value);
        glm::dvec3 out{0.0};
        bool ok = parts.size() == 3;
        for (std::size_t i = 0; ok && i < 3; ++i) {
            const auto v = to_number(parts[i]);
            if (!v) ok = false;
            else out[int(i)] = *v;
        }
        if (!ok)
            fail(a.value_col, "expected 3 comma-separated numbers x,y,z for " + quote(a.key) +
                                  ", got " + quote(a.value));
        return out;
    }
    glm::dvec3 color(const Arg& a) const {
        const glm::dvec3 c = vec3(a);
        if (!(c.x >= 0.0 && c.y >= 0.0 && c.z >= 0.0))
            fail(a.value_col, "colour components of " + quote(a.key) + " must be >= 0, got " +
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
    std::string file_;
    int line_;
    Token word_;
};

// ---- key vocabularies ------------------------------------------------------------------
const std::vector<std::string_view> kMaterialKeys = {"color", "ambi",    "diff", "spec",
                                                     "shininess", "refl", "trans", "ior",
                                                     "checker", "cell"};
const std::vector<std::string_view> kTransformKeys = {"scale", "rotate_x", "rotate_y", "rotate_z",
                                                      "translate"};
const std::vector<std::string_view> kImageKeys = {"width",  "height",  "spp",
                                                  "depth",  "degree",  "output",
                                                  "sampler", "calibration"};
const std::vector<std::string_view> kLookAtKeys = {"eye", "look", "up", "fov"};
const std::vector<std::string_view> kExplicitCameraKeys = {"rx",       "ry",       "df",
                                                           "scale",    "rotate_x", "rotate_y",
                                                           "rotate_z", "translate"};

std::vector<std::string_view> join(std::initializer_list<std::vector<std::string_view>> lists) {
    std::vector<std::string_view> out;
    for (const auto& l : lists) out.insert(out.end(), l.begin(), l.end());
    return out;
}

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
    if (k == "color") ap.color = st.color(a);
    else if (k == "ambi") m.ambi = st.at_least_zero(a);
    else if (k == "diff") m.diff = st.at_least_zero(a);
    else if (k == "spec") m.spec = st.at_least_zero(a);
    else if (k == "shininess") m.shininess = st.at_least_zero(a);
    else if (k == "refl") m.refl = st.at_least_zero(a);
    else if (k == "trans") m.trans = st.at_least_zero(a);
    else if (k == "ior") m.ior = st.positive(a);
    else if (k == "checker") {
        m.checker_color = st.color(a);
        m.checker = true;
    } else if (k == "cell") m.cell = st.positive(a);
    else return false;
    return true;
}

/// Applies one transform key on the left of `md` (written order = application order).
bool apply_transform_key(const Statement& st, const Arg& a, glm::dmat4& md) {
    const auto k = a.key;
    glm::dmat4 t;
    if (k == "scale") t = scale_matrix(st.scale(a));
    else if (k == "rotate_x") t = rotate_x_matrix(st.number(a));
    else if (k == "rotate_y") t = rotate_y_matrix(st.number(a));
    else if (k == "rotate_z") t = rotate_z_matrix(st.number(a));
    else if (k == "translate") t = translate_matrix(st.vec3(a));
    else return false;
    md = t * md;
    return true;
}

std::optional<ShapeKind> shape_from_word(std::string_view w) {
    if (w == "sphere") return ShapeKind::Sphere;
    if (w == "cube") return ShapeKind::Cube;
    if (w == "cylinder") return ShapeKind::Cylinder;
    if (w == "cone") return ShapeKind::Cone;
    if (w == "torus") return ShapeKind::Torus;
    if (w == "plane") return ShapeKind::Plane;
    return std::nullopt;
}

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

bool read_whole_file(const fs::path& p, std::string& out) {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) return false;
    std::ifstream in(p, std::ios::binary);
    if (!in) return false;
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) return false;
    out = ss.str();
    return true;
}

class Parser {
  public:
    Scene scene;

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
            statement(text.substr(pos, nl - pos), display, line_no, depth);
            pos = nl + 1;
        }
        open_.pop_back();
    }

  private:
    std::map<std::string, Appearance, std::less<>> materials_;
    std::vector<fs::path> open_;  // the include chain being read
    std::map<fs::path, std::uint32_t> meshes_;  // by file identity: loaded once, shared (index in scene.meshes)
    std::uint32_t last_file_ = 0;
    int files_ = 0;

    void statement(std::string_view line, const std::string& file, int line_no, int depth) {
        const auto toks = tokenize(line);
        if (toks.empty()) return;
        Statement st(file, line_no, toks[0]);
        const auto w = toks[0].text;
        if (w == "image") image(st, toks);
        else if (w == "ambient") ambient(st, toks);
        else if (w == "background") background(st, toks);
        else if (w == "camera") camera(st, toks);
        else if (w == "light") light(st, toks);
        else if (w == "material") material(st, toks);
        else if (w == "include") include(st, toks, depth);
        else if (w == "mesh") shape(st, toks, ShapeKind::Mesh);
        else if (auto kind = shape_from_word(w)) shape(st, toks, *kind);
        else
            st.fail_here("unknown statement " + quote(w) +
                         " (expected image, ambient, background, camera, light, material, "
                         "sphere, cube, cylinder, cone, torus, plane, mesh or include)");
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
            else if (k == "output") s.output = std::string(a.value);
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
            }
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
        st.read_args(toks, 1, join({kLookAtKeys, kExplicitCameraKeys}));
        Camera cam;
        if (!st.args.empty()) {
            const Arg& first = st.args.front();
            const bool look_at = contains(kLookAtKeys, first.key);
            for (const Arg& a : st.args)
                if (contains(kLookAtKeys, a.key) != look_at)
                    st.fail(a.key_col, "camera: " + quote(a.key) + " belongs to the " +
                                           (look_at ? "explicit" : "look-at") + " form but " +
                                           quote(first.key) + " chose the " +
                                           (look_at ? "look-at" : "explicit") +
                                           " form; use one form per camera statement");
            cam.look_at = look_at;
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
    }

    void light(Statement& st, const std::vector<Token>& toks) {
        if (toks.size() < 2)
            st.fail_here("expected a light kind (point, spot or directional) after 'light'");
        const Token& kt = toks[1];
        Light l;
        std::vector<std::string_view> keys;
        if (kt.text == "point") {
            l.kind = LightKind::Point;
            keys = {"pos", "color"};
        } else if (kt.text == "spot") {
            l.kind = LightKind::Spot;
            keys = {"pos", "dir", "angle", "color"};
        } else if (kt.text == "directional") {
            l.kind = LightKind::Directional;
            keys = {"dir", "color"};
        } else {
            st.fail(kt.column,
                    "expected a light kind (point, spot or directional), got " + quote(kt.text));
        }
        st.read_args(toks, 2, keys);
        for (const Arg& a : st.args) {
            if (a.key == "pos") l.pos = st.vec3(a);
            else if (a.key == "dir") l.dir = st.direction(a);
            else if (a.key == "angle") l.angle = st.in_open(a, 0.0, 180.0);
            else if (a.key == "color") l.color = st.color(a);
        }
        const bool needs_pos = l.kind != LightKind::Directional;
        const bool needs_dir = l.kind != LightKind::Point;
        const std::string kind(kt.text);
        if (needs_pos && !st.find("pos")) st.fail_here("light " + kind + " needs 'pos=x,y,z'");
        if (needs_dir && !st.find("dir")) st.fail_here("light " + kind + " needs 'dir=x,y,z'");
        scene.lights.push_back(l);
    }

    const Appearance& lookup_material(const Statement& st, const Arg& a) const {
        const auto it = materials_.find(a.value);
        if (it == materials_.end())
            st.fail(a.value_col, "unknown material " + quote(a.value) +
                                     " (a material must be defined before it is used)");
        return it->second;
    }

    void material(Statement& st, const std::vector<Token>& toks) {
        if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
            st.fail(toks.size() < 2 ? toks[0].column : toks[1].column,
                    "expected a material name after 'material'");
        const Token& name = toks[1];
        if (const auto it = materials_.find(name.text); it != materials_.end())
            st.fail(name.column, "material " + quote(name.text) + " is already defined");
        std::vector<std::string_view> keys = kMaterialKeys;
        keys.push_back("material");  // a base material to start from
        st.read_args(toks, 2, keys);
        Appearance m;
        if (const Arg* base = st.find("material")) m = lookup_material(st, *base);
        for (const Arg& a : st.args) apply_material_key(st, a, m);
        materials_.emplace(std::string(name.text), m);
    }

    void shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind) {
        std::vector<std::string_view> keys = join({{"material"}, kMaterialKeys, kTransformKeys});
        if (kind == ShapeKind::Torus) keys.push_back("minor");
        if (kind == ShapeKind::Mesh) keys.insert(keys.end(), {"file", "smooth"});
        st.read_args(toks, 1, keys);
        Appearance look;
        if (const Arg* base = st.find("material")) look = lookup_material(st, *base);
        glm::dmat4 md(1.0);
        double minor = 0.25;
        bool smooth = false;
        std::uint32_t mesh = 0;
        bool has_mesh = false;
        for (const Arg& a : st.args) {
            if (a.key == "material") continue;
            if (apply_material_key(st, a, look)) continue;
            if (apply_transform_key(st, a, md)) continue;
            if (a.key == "minor") minor = st.positive(a);
            else if (a.key == "smooth") {
                if (a.value == "true") smooth = true;
                else if (a.value == "false") smooth = false;
                else st.fail(a.value_col, "expected true or false for 'smooth', got " + quote(a.value));
            } else if (a.key == "file") {
                mesh = mesh_file(st, a);
                has_mesh = true;
            }
        }
        if (kind == ShapeKind::Mesh && !has_mesh) st.fail_here("mesh needs 'file=PATH' (a Wavefront OBJ file)");
        if (singular(md))
            st.fail_here(std::string(st.word()) +
                         ": the composed transform is singular (or not finite)");
        add_object(st, kind, md, look, kind == ShapeKind::Torus ? minor : kind == ShapeKind::Mesh ? (smooth ? 1.0 : 0.0) : 0.0,
                   mesh);
    }

    /// Stores one object of the scene (the only place objects are made).
    void add_object(const Statement& st, ShapeKind kind, const glm::dmat4& md, const Appearance& look, double param,
                    std::uint32_t mesh) {
        Object obj;
        obj.kind = kind;
        obj.md = glm::dmat4x3(md);
        obj.param = param;
        obj.color = glm::vec3(look.color);
        obj.mesh = mesh;
        scene.add_object(obj, look.m, ObjectLoc{file_index(st.file()), st.line(), st.where().column});
    }

    /// The index of a file name in Scene::files.
    std::uint32_t file_index(const std::string& file) {
        if (!scene.files.empty() && scene.files[last_file_] == file) return last_file_;
        for (std::uint32_t i = 0; i < scene.files.size(); ++i)
            if (scene.files[i] == file) return last_file_ = i;
        scene.files.push_back(file);
        return last_file_ = std::uint32_t(scene.files.size() - 1);
    }

    /// The mesh of an OBJ file named relative to the statement's file, read once per file:
    /// its index in Scene::meshes.
    std::uint32_t mesh_file(const Statement& st, const Arg& a) {
        const fs::path base = fs::path(st.file()).parent_path();
        const fs::path target = (base / fs::path(std::string(a.value))).lexically_normal();
        const fs::path id = identity_of(target);
        if (const auto it = meshes_.find(id); it != meshes_.end()) return it->second;
        std::error_code ec;
        if (!fs::is_regular_file(target, ec))
            st.fail(a.value_col, "cannot open mesh file " + quote(target.string()));
        try {
            auto mesh = load_obj_mesh(target.string());
            const auto index = std::uint32_t(scene.meshes.size());
            scene.meshes.push_back(std::move(mesh));
            meshes_.emplace(id, index);
            return index;
        } catch (const std::exception& e) {
            st.fail(a.value_col, quote(target.string()) + ": " + e.what());
        }
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
        std::string text;
        if (!read_whole_file(target, text))
            st.fail(t.column, "cannot open included file " + quote(shown));
        read_text(text, shown, id, depth + 1);
    }
};

}  // namespace

Scene load_scene(const std::string& path) {
    std::string text;
    if (!read_whole_file(fs::path(path), text))
        throw SceneError(SourceLoc{path, 0, 0}, "cannot open scene file");
    Parser p;
    p.scene.path = path;
    p.read_text(text, path, identity_of(path), 0);
    return std::move(p.scene);
}

Scene parse_scene(std::string_view text, const std::string& name) {
    Parser p;
    p.scene.path = name;
    p.read_text(text, name, identity_of(name.empty() ? fs::path("<memory>") : fs::path(name)), 0);
    return std::move(p.scene);
}

}  // namespace streamrt
