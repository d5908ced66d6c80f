#include "mesh/obj_reader.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "core/error.h"
#include "core/memory_advice.h"
#include "parallel/parallelism.h"

namespace streamrt {

namespace {

/// Polygons of more corners are fanned: ear clipping takes up to n^3 steps on a hostile one.
constexpr std::uint32_t kEarClipCorners = 256;

bool is_blank(char c) { return c == ' ' || c == '\t'; }
bool is_eol(char c) { return c == '\n' || c == '\r'; }
bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

enum class Word { Other, V, Vt, Vn, F, Usemtl, Mtllib };

/// The statement word starting at p (a line's first non-blank byte); *after is set past it.
/// Both passes classify lines with it, so they agree on which lines are v, vt and vn.
Word statement_word(const char* p, const char* end, const char** after) {
    const char* q = p;
    while (q < end && !is_blank(*q) && !is_eol(*q)) ++q;
    *after = q;
    const std::string_view w(p, std::size_t(q - p));
    if (w == "v") return Word::V;
    if (w == "f") return Word::F;
    if (w == "vt") return Word::Vt;
    if (w == "vn") return Word::Vn;
    if (w == "usemtl") return Word::Usemtl;
    if (w == "mtllib") return Word::Mtllib;
    return Word::Other;
}

/// The start of the line after the one holding p. A line ends at "\n", "\r\n" or a lone "\r",
/// as tinyobjloader read them.
const char* next_line(const char* p, const char* end) {
    const void* n = std::memchr(p, '\n', std::size_t(end - p));
    const char* nl = n ? static_cast<const char*>(n) : end;
    if (const void* r = std::memchr(p, '\r', std::size_t(nl - p))) {
        const char* q = static_cast<const char*>(r) + 1;
        return q < end && *q == '\n' ? q + 1 : q;
    }
    return nl < end ? nl + 1 : end;
}

/// The word at p for a message (core/error.h's quote: one printable line, at most 60 bytes).
std::string quote_at(const char* p, const char* end) {
    const char* q = p;
    while (q < end && !is_blank(*q) && !is_eol(*q) && q - p <= 60) ++q;
    return quote(std::string_view(p, std::size_t(q - p)));
}

struct IndexKind {
    const char* one;
    const char* many;
};
constexpr IndexKind kVertex{"vertex", "vertices"}, kTexcoord{"texture coordinate", "texture coordinates"},
    kNormal{"normal", "normals"};

std::string count_of(std::size_t n, const IndexKind& k) { return std::to_string(n) + " " + (n == 1 ? k.one : k.many); }

/// One chunk of the text: whole lines [begin, end).
struct Chunk {
    const char* begin = nullptr;
    const char* end = nullptr;
    std::size_t v = 0, vt = 0, vn = 0;   // its lines of each kind (first pass)
    std::size_t v_before = 0, vt_before = 0, vn_before = 0, tri_before = 0;  // in the chunks before it
    // Second pass: triangles in file order; a polygon of n corners holds its corners in the
    // first n of its 3(n - 2) slots until it is triangulated (positions are complete only then).
    std::vector<std::uint32_t> tri, tri_uv;
    std::vector<std::pair<std::size_t, std::uint32_t>> polygons;  // first triangle, corners
    struct Use {
        std::size_t triangle;
        std::string_view name;
        const char* at;
    };
    std::vector<Use> uses;  // triangle numbers within the chunk
    struct Gap {
        std::size_t triangle;
        const char* at;
    };
    std::vector<Gap> gaps;
    const char* mtllib_at = nullptr;
    std::string_view mtllib;
    const char* colorless_at = nullptr;  // keep_colors: the chunk's first v line without a colour
    const char* error_at = nullptr;  // the chunk's first error
    std::string error;
};

struct Totals {
    std::size_t v = 0, vt = 0, vn = 0;
};

/// The statement word at p, when p starts a line of chunk c (only blanks before it on its line).
Word word_starting_line(const Chunk& c, const char* p, const char** after) {
    const char* b = p;
    while (b > c.begin && is_blank(b[-1])) --b;
    *after = p + 1;
    return b == c.begin || is_eol(b[-1]) ? statement_word(p, c.end, after) : Word::Other;
}

/// First pass: the chunk's v, vt and vn lines, found by jumping from 'v' to 'v' (face lines
/// have none).
void count_lines(Chunk& c) {
    for (const char* p = c.begin; p < c.end;) {
        const void* v = std::memchr(p, 'v', std::size_t(c.end - p));
        if (!v) break;
        switch (word_starting_line(c, static_cast<const char*>(v), &p)) {
        case Word::V: ++c.v; break;
        case Word::Vt: ++c.vt; break;
        case Word::Vn: ++c.vn; break;
        default: break;
        }
    }
}

struct Failure {
    const char* at;
    std::string message;
};

/// Second pass over one chunk: positions and texture coordinates into their final place,
/// faces into the chunk's triangles; throws Failure at the chunk's first error.
class ChunkReader {
  public:
    ChunkReader(Chunk& c, const Totals& totals, ObjData& out, bool keep_uv)
        : c_(c), p_(c.begin), end_(c.end), totals_(totals), positions_(out.positions.data()),
          texcoords_(out.texcoords.data()), colors_(out.colors.empty() ? nullptr : out.colors.data()),
          keep_uv_(keep_uv) {}

    void run() {
        while (p_ < end_) {
            skip_blanks();
            if (p_ == end_) break;
            if (*p_ == '#' || is_eol(*p_)) {
                p_ = next_line(p_, end_);
                continue;
            }
            const char* word = p_;
            switch (statement_word(p_, end_, &p_)) {
            case Word::V: vertex(word); break;
            case Word::Vt: texcoord(); break;
            case Word::F: face(word); break;
            case Word::Vn:
                ++vn_;
                p_ = next_line(p_, end_);
                continue;
            case Word::Usemtl:
                c_.uses.push_back({c_.tri.size() / 3, name(), word});
                gap_seen_ = false;
                p_ = next_line(p_, end_);
                continue;
            case Word::Mtllib:
                if (!c_.mtllib_at) {
                    c_.mtllib = name();
                    if (!c_.mtllib.empty()) c_.mtllib_at = word;
                }
                p_ = next_line(p_, end_);
                continue;
            case Word::Other:
                p_ = next_line(p_, end_);
                continue;
            }
            // The statement's values are read up to the line's end or a comment.
            p_ = p_ < end_ && *p_ == '#' ? next_line(p_, end_) : skip_eol(p_);
        }
    }

  private:
    [[noreturn]] void fail(const char* at, std::string message) const { throw Failure{at, std::move(message)}; }
    std::string got(const char* at) const {
        if (at == end_ || is_eol(*at)) return " before the end of the line";
        if (is_blank(*at)) return ", got a blank";
        if (*at == '\\' && (at + 1 == end_ || is_eol(at[1]))) return ", got '\\' (lines are not continued: one statement a line)";
        return ", got " + quote_at(at, end_);
    }
    void skip_blanks() {
        const char* p = p_;
        while (p < end_ && is_blank(*p)) ++p;
        p_ = p;
    }
    const char* skip_eol(const char* p) const {
        if (p == end_) return p;
        if (*p == '\r' && p + 1 < end_ && p[1] == '\n') return p + 2;
        return p + 1;
    }
    /// Skips blanks; true at the line's end or a comment.
    bool line_done() {
        skip_blanks();
        return p_ == end_ || is_eol(*p_) || *p_ == '#';
    }
    bool value_ends(const char* q) const { return q == end_ || is_blank(*q) || is_eol(*q) || *q == '#'; }

    /// The name after usemtl or mtllib (its first word; the rest of the line is ignored).
    std::string_view name() {
        skip_blanks();
        const char* n = p_;
        while (p_ < end_ && !is_blank(*p_) && !is_eol(*p_)) ++p_;
        return {n, std::size_t(p_ - n)};
    }

    [[gnu::always_inline]] float number(const char* what) {
        skip_blanks();
        if (float f; short_decimal(f)) return f;
        return any_number(what);
    }
    [[gnu::noinline]] float any_number(const char* what) {
        const char* s = p_;
        const char* q = s;
        if (q < end_ && *q == '+') {  // from_chars takes no '+'
            ++q;
            if (q == end_ || !(is_digit(*q) || *q == '.')) fail(s, std::string("expected ") + what + got(s));
        }
        float f = 0;
        const auto [e, ec] = std::from_chars(q, end_, f);
        if (ec == std::errc::invalid_argument || !value_ends(e)) fail(s, std::string("expected ") + what + got(s));
        if (ec == std::errc::result_out_of_range) f = beyond_float(q, e, s);
        if (!std::isfinite(f)) fail(s, quote_at(s, end_) + " is not a finite number");
        p_ = e;
        return f;
    }
    /// The number at p_ when it is a plain decimal of at most 9 digits, value below 2^24 once
    /// the point is dropped and at most 10 digits after it (most exporters' "%.6f"): then
    /// m / 10^k in float, both exact, is the correctly rounded value from_chars gives, 4x faster.
    [[gnu::always_inline]] bool short_decimal(float& out) {
        static constexpr float kPow10[] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f, 1e8f, 1e9f, 1e10f};
        const char* q = p_;
        const bool minus = q < end_ && *q == '-';
        q += minus;
        std::uint32_t m = 0;
        int digits = 0, decimals = 0;
        for (; q < end_ && is_digit(*q) && digits < 10; ++q, ++digits) m = m * 10 + std::uint32_t(*q - '0');
        if (q < end_ && *q == '.')
            for (++q; q < end_ && is_digit(*q) && digits < 10; ++q, ++digits, ++decimals) m = m * 10 + std::uint32_t(*q - '0');
        if (digits == 0 || digits == 10 || m > (1u << 24) || !value_ends(q)) return false;
        const float f = float(m) / kPow10[decimals];
        out = minus ? -f : f;
        p_ = q;
        return true;
    }
    /// A number from_chars finds out of the float range: one too small is 0 (tinyobjloader
    /// read it so), one too large is refused.
    float beyond_float(const char* q, const char* e, const char* s) const {
        long double x = 0;
        if (std::from_chars(q, e, x).ec == std::errc() && std::fabs(x) < 1) return float(x);
        fail(s, quote_at(s, end_) + " is beyond the float range");
    }

    /// A face corner's index (1-based, or negative: relative to the `seen` before this line),
    /// checked against the file's `total`; returned from 0.
    [[gnu::always_inline]] std::uint32_t index(std::size_t seen, std::size_t total, const IndexKind& k) {
        const char* s = p_;
        const char* p = p_;  // a local: a store to p_ per digit otherwise (chars may alias it)
        const bool minus = p < end_ && *p == '-';
        if (p < end_ && (*p == '-' || *p == '+')) ++p;
        const char* digits = p;
        std::uint64_t n = 0;
        for (; p < end_ && is_digit(*p); ++p) n = n * 10 + std::uint64_t(*p - '0');
        p_ = p;
        if (std::size_t(p - digits) - 1 < 12) {  // 1 to 12 digits (more: beyond any count, and n may have wrapped)
            if (!minus && n - 1 < total) return std::uint32_t(n - 1);
            if (minus && n - 1 < seen) return std::uint32_t(seen - n);
        }
        bad_index(s, digits, minus, seen, total, k);
    }
    [[noreturn, gnu::cold, gnu::noinline]] void bad_index(const char* s, const char* digits, bool minus, std::size_t seen,
                                                         std::size_t total, const IndexKind& k) const {
        if (p_ == digits) fail(s, std::string("expected a ") + k.one + " index" + got(s));
        const std::string text(s, p_);
        if (p_ - digits == std::count(digits, p_, '0')) fail(s, std::string(k.one) + " index " + text + " (OBJ numbers them from 1)");
        if (!minus) fail(s, std::string(k.one) + " index " + text + " is out of range: the file has " + count_of(total, k));
        fail(s, std::string("relative ") + k.one + " index " + text + " reaches before the first " + k.one + " (" +
                    count_of(seen, k) + " so far)");
    }

    void vertex(const char* word) {
        if (v_ == c_.v) fail(p_, "internal error: more vertex lines than counted");  // memory safety only
        float* out = positions_ + 3 * (c_.v_before + v_);
        for (int a = 0; a < 3; ++a) out[a] = number("a vertex coordinate (v x y z)");
        if (colors_) {
            vertex_color(word, colors_ + 3 * (c_.v_before + v_));
        } else {
            for (int extra = 0; !line_done(); ++extra) {
                if (extra == 4) fail(p_, "unexpected " + quote_at(p_, end_) + " after a vertex's x y z and 4 more numbers (w or a colour)");
                number("a number (a vertex's w or colour)");
            }
        }
        ++v_;
    }

    /// The numbers after a vertex's x y z when colours are kept: `r g b` (and an alpha, not
    /// kept), the extension MeshLab and others write; a single one is the w of homogeneous
    /// coordinates, no colour. Out of vertex(): its loop stays as tight as before without them.
    [[gnu::noinline]] void vertex_color(const char* word, float* rgb) {
        float extra[4];
        int n = 0;
        for (; !line_done(); ++n) {
            if (n == 4) fail(p_, "unexpected " + quote_at(p_, end_) + " after a vertex's x y z and 4 more numbers (w or a colour)");
            extra[n] = number("a number (a vertex's w or colour)");
        }
        if (n >= 3) {
            std::copy_n(extra, 3, rgb);
        } else {
            std::fill_n(rgb, 3, 0.f);
            if (!c_.colorless_at) c_.colorless_at = word;
        }
    }

    void texcoord() {
        if (vt_ == c_.vt) fail(p_, "internal error: more vt lines than counted");
        float* out = texcoords_ + 2 * (c_.vt_before + vt_);
        out[0] = number("a texture coordinate (vt u [v [w]])");
        out[1] = line_done() ? 0.f : number("a texture coordinate (vt u [v [w]])");
        if (!line_done()) number("a texture coordinate (vt u [v [w]])");
        if (!line_done()) fail(p_, "unexpected " + quote_at(p_, end_) + " after a texture coordinate's u v w");
        ++vt_;
    }

    void face(const char* word) {
        // Corners go straight into the chunk's triangles: a triangle fills its 3 slots, a
        // polygon of n corners its first n of 3(n - 2) (the rest 0 until it is triangulated).
        const std::size_t first = c_.tri.size() / 3;
        const char* without_uv = nullptr;  // the first corner without vt
        std::size_t n = 0;
        for (; !line_done(); ++n) {
            const char* at = p_;
            c_.tri.push_back(index(c_.v_before + v_, totals_.v, kVertex));
            std::uint32_t vt = ObjData::kNoUv;
            if (p_ < end_ && *p_ == '/') {
                ++p_;
                if (p_ < end_ && *p_ == '/') {
                    ++p_;
                    index(c_.vn_before + vn_, totals_.vn, kNormal);
                } else {
                    vt = index(c_.vt_before + vt_, totals_.vt, kTexcoord);
                    if (p_ < end_ && *p_ == '/') {
                        ++p_;
                        index(c_.vn_before + vn_, totals_.vn, kNormal);
                    }
                }
            }
            if (!value_ends(p_))
                fail(p_, "unexpected " + quote_at(p_, end_) + " in a face corner (v, v/vt, v//vn or v/vt/vn)");
            if (vt == ObjData::kNoUv && !without_uv) without_uv = at;
            if (keep_uv_) c_.tri_uv.push_back(vt);
        }
        if (n < 3) fail(word, "a face needs at least 3 corners, got " + std::to_string(n));
        if (keep_uv_ && without_uv && !gap_seen_) {
            c_.gaps.push_back({first, without_uv});
            gap_seen_ = true;
        }
        if (n == 3) return;
        c_.polygons.emplace_back(first, std::uint32_t(n));
        c_.tri.resize(3 * (first + n - 2));
        if (keep_uv_) c_.tri_uv.resize(3 * (first + n - 2));
    }
    Chunk& c_;
    const char* p_;
    const char* const end_;
    const Totals& totals_;
    float* const positions_;
    float* const texcoords_;
    float* const colors_;  // keep_colors only
    const bool keep_uv_;
    std::size_t v_ = 0, vt_ = 0, vn_ = 0;  // lines of each kind read so far in the chunk
    bool gap_seen_ = false;                // a gap recorded since the chunk's start or the last usemtl
};

/// tinyobjloader's ear clipping of a polygon (corners' vertex numbers `v`, positions `pos`),
/// step for step and in float as it computed, so files keep their triangles. Where it gave up
/// (no ear in a whole round, e.g. a self-crossing outline) and dropped the rest, the rest is
/// fanned instead. emit(a, b, c) takes corner numbers; called n - 2 times.
template <class Emit>
void ear_clip(const float* pos, const std::vector<std::uint32_t>& v, std::vector<std::uint32_t>& ring, Emit&& emit) {
    const std::size_t n = v.size();
    const auto at = [&](std::uint32_t corner, int axis) { return pos[3 * std::size_t(v[corner]) + std::size_t(axis)]; };
    // The projection plane: at the first turn with a cross product component above float
    // epsilon, leave out the axis of its largest component (x on ties goes to y: as it did).
    int ax = 1, ay = 2;
    for (std::size_t k = 0; k < n; ++k) {
        const auto a = std::uint32_t(k), b = std::uint32_t((k + 1) % n), c = std::uint32_t((k + 2) % n);
        const float e0x = at(b, 0) - at(a, 0), e0y = at(b, 1) - at(a, 1), e0z = at(b, 2) - at(a, 2);
        const float e1x = at(c, 0) - at(b, 0), e1y = at(c, 1) - at(b, 1), e1z = at(c, 2) - at(b, 2);
        const float cx = std::fabs(e0y * e1z - e0z * e1y), cy = std::fabs(e0z * e1x - e0x * e1z),
                    cz = std::fabs(e0x * e1y - e0y * e1x);
        constexpr float eps = std::numeric_limits<float>::epsilon();
        if (cx > eps || cy > eps || cz > eps) {
            if (!(cx > cy && cx > cz)) {
                ax = 0;
                if (cz > cx && cz > cy) ay = 1;
            }
            break;
        }
    }
    ring.resize(n);
    for (std::size_t k = 0; k < n; ++k) ring[k] = std::uint32_t(k);
    std::size_t guess = 0, tries = n, last_size = n;
    while (ring.size() > 3 && tries > 0) {
        const std::size_t m = ring.size();
        if (guess >= m) guess -= m;
        if (last_size != m) {
            last_size = m;
            tries = m;
        } else {
            --tries;
        }
        float x[3], y[3];
        for (int k = 0; k < 3; ++k) {
            x[k] = at(ring[(guess + std::size_t(k)) % m], ax);
            y[k] = at(ring[(guess + std::size_t(k)) % m], ay);
        }
        const float cross = (x[1] - x[0]) * (y[2] - y[1]) - (y[1] - y[0]) * (x[2] - x[1]);
        const float area = (x[0] * y[1] - y[0] * x[1]) * 0.5f;  // (sic: about the origin)
        if (cross * area < 0.f) {
            ++guess;
            continue;
        }
        bool inside = false;
        for (std::size_t o = 3; o < m && !inside; ++o) {
            const float tx = at(ring[(guess + o) % m], ax), ty = at(ring[(guess + o) % m], ay);
            for (int i = 0, j = 2; i < 3; j = i++)  // crossings of a ray from (tx, ty)
                if ((y[i] > ty) != (y[j] > ty) && tx < (x[j] - x[i]) * (ty - y[i]) / (y[j] - y[i]) + x[i])
                    inside = !inside;
        }
        if (inside) {
            ++guess;
            continue;
        }
        emit(ring[guess % m], ring[(guess + 1) % m], ring[(guess + 2) % m]);
        ring.erase(ring.begin() + std::ptrdiff_t((guess + 1) % m));
    }
    for (std::size_t k = 1; k + 1 < ring.size(); ++k) emit(ring[0], ring[k], ring[k + 1]);
}

/// Cuts the polygon whose n corners are tri[0, n) (and uv[0, n), when uv) into the n - 2
/// triangles over tri[0, 3(n - 2)), as tinyobjloader did: a quad along its shorter diagonal
/// (on a tie the one from its second corner to its fourth), larger ones by ear clipping
/// (fanned beyond kEarClipCorners).
void triangulate(const float* pos, std::uint32_t* tri, std::uint32_t* uv, std::uint32_t n,
                 std::vector<std::uint32_t> (&scratch)[3]) {
    std::vector<std::uint32_t>& v = scratch[0];
    std::vector<std::uint32_t>& t = scratch[1];
    v.assign(tri, tri + n);
    if (uv) t.assign(uv, uv + n);
    std::size_t k = 0;
    const auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const std::uint32_t corner[3] = {a, b, c};
        for (int j = 0; j < 3; ++j) {
            tri[3 * k + std::size_t(j)] = v[corner[j]];
            if (uv) uv[3 * k + std::size_t(j)] = t[corner[j]];
        }
        ++k;
    };
    if (n == 4) {
        const auto sq = [&](std::uint32_t a, std::uint32_t b) {
            const float* p = pos + 3 * std::size_t(v[a]);
            const float* q = pos + 3 * std::size_t(v[b]);
            const float dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
            return dx * dx + dy * dy + dz * dz;
        };
        if (sq(0, 2) < sq(1, 3)) {
            emit(0, 1, 2);
            emit(0, 2, 3);
        } else {
            emit(0, 1, 3);
            emit(1, 2, 3);
        }
    } else if (n <= kEarClipCorners) {
        ear_clip(pos, v, scratch[2], emit);
    } else {
        for (std::uint32_t c = 1; c + 1 < n; ++c) emit(0, c, c + 1);
    }
}

/// Cuts `bytes` into chunks of about `size` bytes, each ending after a '\n' (or at the end);
/// a UTF-8 byte order mark (Windows tools write one) is left out.
std::vector<Chunk> cut(std::string_view bytes, std::size_t size) {
    std::vector<Chunk> chunks;
    size = std::max<std::size_t>(size, 1);
    for (std::size_t pos = bytes.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0; pos < bytes.size();) {
        std::size_t end = bytes.size();
        if (bytes.size() - pos > size) {
            const std::size_t nl = bytes.find('\n', pos + size - 1);
            if (nl != std::string_view::npos) end = nl + 1;
        }
        Chunk c;
        c.begin = bytes.data() + pos;
        c.end = bytes.data() + end;
        chunks.push_back(std::move(c));
        pos = end;
    }
    return chunks;
}

/// The offset of chunk c's k-th (from 0) v line's word (as count_lines finds them).
std::size_t vertex_line(std::string_view bytes, const Chunk& c, std::size_t k) {
    for (const char* p = c.begin; p < c.end;) {
        const char* v = static_cast<const char*>(std::memchr(p, 'v', std::size_t(c.end - p)));
        if (!v) break;
        if (word_starting_line(c, v, &p) == Word::V && k-- == 0) return std::size_t(v - bytes.data());
    }
    return std::size_t(c.begin - bytes.data());
}

}  // namespace

void obj_fail_at(std::string_view bytes, const std::string& name, std::size_t offset, const std::string& message) {
    offset = std::min(offset, bytes.size());
    std::size_t line = 1, start = 0;
    for (std::size_t i = 0; i < offset; ++i)
        if (bytes[i] == '\n' || (bytes[i] == '\r' && (i + 1 == bytes.size() || bytes[i + 1] != '\n'))) {
            ++line;
            start = i + 1;
        }
    if (line == 1 && bytes.substr(0, 3) == "\xEF\xBB\xBF") start = std::min<std::size_t>(3, offset);  // columns after the mark
    throw std::runtime_error(name + ":" + std::to_string(line) + ":" + std::to_string(offset - start + 1) + ": " +
                             message);
}

ObjData parse_obj(std::string_view bytes, const std::string& name, const ObjReadOptions& options) {
    std::vector<Chunk> chunks = cut(bytes, options.chunk_bytes);
    parallel_for_index(chunks.size(), 1, [&](std::size_t k) { count_lines(chunks[k]); });
    Totals totals;
    for (Chunk& c : chunks) {
        c.v_before = totals.v, c.vt_before = totals.vt, c.vn_before = totals.vn;
        if (totals.v + c.v > options.max_vertices)
            obj_fail_at(bytes, name, vertex_line(bytes, c, options.max_vertices - totals.v),
                        "more than " + count_of(options.max_vertices, kVertex));
        totals.v += c.v, totals.vt += c.vt, totals.vn += c.vn;
    }

    MemoryBudget* const budget = options.budget;
    if (budget)
        budget->need(double(totals.v) * sizeof(float) * (options.keep_colors ? 6 : 3) +
                         double(totals.vt) * 2 * sizeof(float),
                     "its " + count_of(totals.v, kVertex) +
                         (totals.vt > 0 ? " and " + count_of(totals.vt, kTexcoord) : std::string()));
    ObjData out;
    // Huge pages for the large arrays (some faults instead of thousands), asked for before
    // they are first written.
    const auto fresh = [](auto& v, std::size_t n) {
        v.reserve(n);
        want_huge_pages(v.data(), n);
        v.resize(n);
    };
    fresh(out.positions, 3 * totals.v);
    out.texcoords.resize(2 * totals.vt);
    if (options.keep_colors) fresh(out.colors, 3 * totals.v);
    out.normal_count = totals.vn;
    // The faces' memory is known only once their lines are read: each chunk counts what it
    // took, and the chunks not started yet are skipped once the budget is passed (past it
    // by at most a chunk's faces per thread).
    const double face_room = budget ? budget->left() : 0.0;
    std::atomic<std::size_t> face_bytes{0};
    std::atomic<bool> past_budget{false};
    parallel_for_index(chunks.size(), 1, [&](std::size_t k) {
        if (past_budget.load(std::memory_order_relaxed)) return;
        Chunk& c = chunks[k];
        c.tri.reserve(std::size_t(c.end - c.begin) / 6);  // "f 1 2 3\n" lines of 6-digit numbers, without growing
        if (options.keep_uv) c.tri_uv.reserve(c.tri.capacity());
        try {
            ChunkReader(c, totals, out, options.keep_uv).run();
        } catch (const Failure& f) {
            c.error_at = f.at;
            c.error = f.message;
        }
        const std::size_t took = (c.tri.size() + c.tri_uv.size()) * sizeof(std::uint32_t);
        if (budget && double(face_bytes.fetch_add(took) + took) > face_room) past_budget.store(true);
    });
    std::size_t chunk_triangles = 0;
    for (const Chunk& c : chunks) chunk_triangles += c.tri.size() / 3;
    if (budget) budget->need(double(face_bytes.load()), "its faces (" + std::to_string(chunk_triangles) + " triangles read so far)");
    for (const Chunk& c : chunks)  // the first error in the file
        if (c.error_at) obj_fail_at(bytes, name, std::size_t(c.error_at - bytes.data()), c.error);
    for (const Chunk& c : chunks)  // the first vertex without a colour in the file
        if (c.colorless_at) {
            out.colorless_offset = std::size_t(c.colorless_at - bytes.data());
            break;
        }

    std::size_t triangles = 0;
    for (Chunk& c : chunks) {
        c.tri_before = triangles;
        triangles += c.tri.size() / 3;
    }
    // Copied out of the chunks, which are freed as they go: both are held only chunk by chunk.
    if (budget)
        budget->need(double(triangles) * 3 * sizeof(std::uint32_t) * (options.keep_uv ? 2 : 1),
                     "its " + std::to_string(triangles) + " triangles");
    fresh(out.triangles, 3 * triangles);
    if (options.keep_uv) fresh(out.triangle_uv, 3 * triangles);
    parallel_for_index(chunks.size(), 1, [&](std::size_t k) {
        Chunk& c = chunks[k];
        std::uint32_t* tri = out.triangles.data() + 3 * c.tri_before;
        std::uint32_t* uv = options.keep_uv ? out.triangle_uv.data() + 3 * c.tri_before : nullptr;
        std::copy(c.tri.begin(), c.tri.end(), tri);
        if (uv) std::copy(c.tri_uv.begin(), c.tri_uv.end(), uv);
        std::vector<std::uint32_t>().swap(c.tri);
        std::vector<std::uint32_t>().swap(c.tri_uv);
        std::vector<std::uint32_t> scratch[3];
        for (const auto& [first, n] : c.polygons)
            triangulate(out.positions.data(), tri + 3 * first, uv ? uv + 3 * first : nullptr, n, scratch);
    });
    if (budget) budget->release(double(face_bytes.load()));

    const char* library = nullptr;
    for (const Chunk& c : chunks)
        if (c.mtllib_at) {
            library = c.mtllib_at;
            out.mtllib = std::string(c.mtllib);
            break;
        }
    // Uses and gaps in file order (a usemtl line comes before a face of the same triangle
    // number); a run's first gap only, whatever the chunks.
    bool run_has_gap = false;
    for (const Chunk& c : chunks)
        for (std::size_t u = 0, g = 0; u < c.uses.size() || g < c.gaps.size();) {
            if (g == c.gaps.size() || (u < c.uses.size() && c.uses[u].triangle <= c.gaps[g].triangle)) {
                const Chunk::Use& use = c.uses[u++];
                out.material_uses.push_back({c.tri_before + use.triangle, std::string(use.name), !library || use.at < library});
                run_has_gap = false;
            } else {
                const Chunk::Gap& gap = c.gaps[g++];
                if (!run_has_gap) out.uv_gaps.push_back({c.tri_before + gap.triangle, std::size_t(gap.at - bytes.data())});
                run_has_gap = true;
            }
        }
    return out;
}

}  // namespace streamrt
