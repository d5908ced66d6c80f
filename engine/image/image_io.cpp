#include "image/image_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <fcntl.h>
#include <limits.h>
#include <sys/uio.h>
#include <unistd.h>
#include <zlib.h>

#include <system_error>

#include "core/error.h"
#include "image/exr_io.h"
#include "parallel/parallelism.h"

// The only translation unit that includes stb (for reading PNG back).
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb_image.h>

namespace streamrt {

namespace fs = std::filesystem;

std::optional<ImageFormat> image_format_for(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".ppm") return ImageFormat::Ppm;
    if (ext == ".png") return ImageFormat::Png;
    if (ext == ".pfm") return ImageFormat::Pfm;
    if (ext == ".exr") return ImageFormat::Exr;
    return std::nullopt;
}

Display display_of(const RenderSettings& s) {
    Display d;
    d.calibration = s.calibration;
    d.colorspace = s.colorspace;
    d.tonemap = s.tonemap;
    d.exposure = float(s.exposure);
    d.exr = s.exr;
    return d;
}

double srgb_oetf(double c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }

Framebuffer calibrate(const Framebuffer& fb, Calibration how) {
    Framebuffer out = fb;
    float scale = 1.f;
    if (how == Calibration::Normalize) {
        float peak = 0.f;
        for (float v : fb.rgb)
            if (std::isfinite(v)) peak = std::max(peak, v);
        if (peak > 0.f) scale = 1.f / peak;
    }
    for (float& v : out.rgb) v = std::isfinite(v) ? std::clamp(v * scale, 0.f, 1.f) : 0.f;
    return out;
}

namespace {

struct Cancelled {};

// Runs body(i) for i in [0, n), on the writer's threads when it has any.
template <class Body>
void for_each(Parallelism* par, std::size_t n, std::size_t grain, Body&& body) {
    if (par) par->for_each_index(n, grain, body);
    else
        for (std::size_t i = 0; i < n; ++i) body(i);
}

// The largest finite value of the framebuffer (0 if none is positive): one read pass.
float finite_peak(const Framebuffer& fb, Parallelism* par) {
    const std::size_t rows = std::size_t(fb.height), row_floats = std::size_t(fb.width) * 3;
    std::vector<float> row_peak(rows, 0.f);
    for_each(par, rows, 16, [&](std::size_t y) {
        float peak = 0.f;
        for (const float* v = fb.pixel(0, int(y)); v != fb.pixel(0, int(y)) + row_floats; ++v)
            if (std::isfinite(*v)) peak = std::max(peak, *v);
        row_peak[y] = peak;
    });
    return rows ? *std::max_element(row_peak.begin(), row_peak.end()) : 0.f;
}

// ThreadSanitizer instruments the clones' load-time resolver, which then runs before TSan is
// set up and crashes every binary: TSan builds take the one default version.
#if defined(__SANITIZE_THREAD__)
#define STREAMRT_ROW_CLONES
#else
#define STREAMRT_ROW_CLONES __attribute__((target_clones("avx2", "default")))
#endif

// calibrate() and lround(c * 255) fused, one row at a time, in a form GCC vectorises:
// |v| <= FLT_MAX is isfinite, and for y >= 0 "trunc, plus one if the exact remainder is at
// least a half" is lround (y + 0.5f would round wrongly just below a half). The file is built
// with -fno-trapping-math (engine/CMakeLists.txt) so that GCC turns the selects into blends;
// an AVX2 clone (chosen at load time) converts 3x faster than SSE2 (docs/performance.md).
// Exact integer rounding and one multiply: every clone gives the same bytes.
STREAMRT_ROW_CLONES void row_to_bytes(const Framebuffer& fb, int y, float scale,
                                                                    unsigned char* __restrict out) {
    const float* __restrict v = fb.pixel(0, y);
    const std::size_t n = std::size_t(fb.width) * 3;
    for (std::size_t i = 0; i < n; ++i) {
        const bool finite = (std::bit_cast<std::uint32_t>(v[i]) & 0x7f800000u) != 0x7f800000u;
        const float x = v[i] * scale;
        const float low = x < 0.f ? 0.f : x;
        const float high = low > 1.f ? 1.f : low;
        const float c = finite ? high : 0.f;
        const float scaled = c * 255.f;
        const int whole = static_cast<int>(scaled);
        out[i] = static_cast<unsigned char>(whole + (scaled - float(whole) >= 0.5f ? 1 : 0));
    }
}

// ---- display colour (docs/scene-format.md, "Output and display colour") ----------------
// The sRGB OETF and 8-bit rounding, exactly lround(255 srgb_oetf(c)) in double for every
// float c in [0, 1], from two small tables: the code at the start of each 1/4096 step of c,
// and for each code the smallest float c that rounds to the next one. The curve rises by
// at most 255 * 12.92 / 4096 = 0.80 codes per step, so a step crosses one threshold at most:
// code = start[i] + (c >= up[start[i]]). int32 tables: the AVX2 clone gathers from them.
struct SrgbTables {
    static constexpr int kSteps = 4096;
    std::int32_t start[kSteps + 1];
    float up[256];  // up[255] is above every c

    SrgbTables() {
        const auto code = [](float c) { return int(std::lround(255.0 * srgb_oetf(double(c)))); };
        for (int k = 0; k < 255; ++k) {
            // Floats in [0, 1] are ordered like their bit patterns: bisect on those.
            std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.f);  // code(lo) <= k < code(hi)
            while (hi - lo > 1) {
                const std::uint32_t mid = lo + (hi - lo) / 2;
                (code(std::bit_cast<float>(mid)) > k ? hi : lo) = mid;
            }
            up[k] = std::bit_cast<float>(hi);
        }
        up[255] = 2.f;
        for (int i = 0; i <= kSteps; ++i) start[i] = code(float(i) / kSteps);
    }
};

const SrgbTables& srgb_tables() {
    static const SrgbTables tables;
    return tables;
}

// One row of exposure, tone curve, calibration, encoding and rounding, in the vectorisable
// form of row_to_bytes (inlined into each clone below, so it is compiled for each target).
// `pre` multiplies first (the exposure, or the whole clamp-and-scale factor), `post` after
// the tone curve (normalize's 1 / max). Values above 1e30 are taken as 1e30 (Reinhard of
// them is 1), NaN and infinities as 0.
template <bool kReinhard, bool kSrgb>
[[gnu::always_inline]] inline void display_row_body(const Framebuffer& fb, int y, float pre, float post,
                                                    const SrgbTables* t, unsigned char* __restrict out) {
    const float* __restrict v = fb.pixel(0, y);
    const std::size_t n = std::size_t(fb.width) * 3;
    for (std::size_t i = 0; i < n; ++i) {
        const bool finite = (std::bit_cast<std::uint32_t>(v[i]) & 0x7f800000u) != 0x7f800000u;
        const float x = v[i] * pre;
        float low = x < 0.f ? 0.f : x;
        if constexpr (kReinhard) {
            low = low > 1e30f ? 1e30f : low;
            low = low / (1.f + low) * post;
        }
        const float high = low > 1.f ? 1.f : low;
        const float c = finite ? high : 0.f;
        if constexpr (kSrgb) {
            const std::int32_t code = t->start[static_cast<int>(c * float(SrgbTables::kSteps))];
            out[i] = static_cast<unsigned char>(code + (c >= t->up[code] ? 1 : 0));
        } else {
            const float scaled = c * 255.f;
            const int whole = static_cast<int>(scaled);
            out[i] = static_cast<unsigned char>(whole + (scaled - float(whole) >= 0.5f ? 1 : 0));
        }
    }
}

STREAMRT_ROW_CLONES void row_clamp_srgb(const Framebuffer& fb, int y, float pre, float post, const SrgbTables* t,
                                        unsigned char* __restrict out) {
    display_row_body<false, true>(fb, y, pre, post, t, out);
}
STREAMRT_ROW_CLONES void row_reinhard_srgb(const Framebuffer& fb, int y, float pre, float post, const SrgbTables* t,
                                           unsigned char* __restrict out) {
    display_row_body<true, true>(fb, y, pre, post, t, out);
}
STREAMRT_ROW_CLONES void row_reinhard_linear(const Framebuffer& fb, int y, float pre, float post, const SrgbTables* t,
                                             unsigned char* __restrict out) {
    display_row_body<true, false>(fb, y, pre, post, t, out);
}

// The 8-bit rows of one image for one Display, its factors found once (the normalize
// maximum's pass included). Linear, clamp, exposure 1 is the handout's row_to_bytes.
class EightBitRows {
  public:
    EightBitRows(const Framebuffer& fb, const Display& d, Parallelism* par) : fb_(fb) {
        const bool normalize = d.calibration == Calibration::Normalize;
        const float peak = normalize ? finite_peak(fb, par) : 0.f;
        if (d.tonemap == Tonemap::Clamp) {
            // v * e clamped, or v * e / max(v * e) = v / max(v): one factor.
            pre_ = normalize ? (peak > 0.f ? 1.f / peak : 1.f) : d.exposure;
            row_ = d.colorspace == ColorSpace::Srgb ? &row_clamp_srgb : nullptr;
        } else {
            // Reinhard is increasing: the maximum after the curve is the curve of the maximum.
            pre_ = d.exposure;
            const float x = std::min(peak * d.exposure, 1e30f), top = x / (1.f + x);
            post_ = normalize && top > 0.f ? 1.f / top : 1.f;
            row_ = d.colorspace == ColorSpace::Srgb ? &row_reinhard_srgb : &row_reinhard_linear;
        }
        if (d.colorspace == ColorSpace::Srgb) tables_ = &srgb_tables();
    }
    void operator()(int y, unsigned char* out) const {
        if (row_) row_(fb_, y, pre_, post_, tables_, out);
        else row_to_bytes(fb_, y, pre_, out);
    }

  private:
    using Row = void (*)(const Framebuffer&, int, float, float, const SrgbTables*, unsigned char*);  // tables: sRGB rows only
    const Framebuffer& fb_;
    float pre_ = 1.f, post_ = 1.f;
    Row row_ = nullptr;
    const SrgbTables* tables_ = nullptr;
};

constexpr std::size_t kPpmChunkBytes = std::size_t(4) << 20;  // one write() per 4 MiB
constexpr std::size_t kPngBandBytes = std::size_t(128) << 10;
constexpr std::size_t kPngBandsInFlight = 16;  // encoded together, then written in order
// deflate's state for windowBits 15, memLevel 8 (zlib's zconf.h), plus its own bookkeeping.
constexpr double kDeflateStateBytes = (1 << 17) + (1 << 17) + 8192;

std::size_t ppm_chunk_rows(int width) {
    return std::max<std::size_t>(1, kPpmChunkBytes / (std::size_t(width) * 3));
}

std::string ppm_pfm_header(const char* magic, const Framebuffer& fb, const char* third) {
    return std::string(magic) + "\n" + std::to_string(fb.width) + " " + std::to_string(fb.height) + "\n" + third +
           "\n";
}

void encode_ppm(const Framebuffer& fb, const EightBitRows& to_bytes, const ByteSink& sink, const WriteOptions& o) {
    const std::string header = ppm_pfm_header("P6", fb, "255");
    const std::size_t stride = std::size_t(fb.width) * 3, chunk = ppm_chunk_rows(fb.width);
    std::vector<unsigned char> buf(std::min(chunk, std::size_t(fb.height)) * stride);
    for (std::size_t y0 = 0; y0 < std::size_t(fb.height); y0 += chunk) {
        if (o.cancel && o.cancel->load()) throw Cancelled{};
        const std::size_t rows = std::min(chunk, std::size_t(fb.height) - y0);
        for_each(o.par, rows, 16, [&](std::size_t r) { to_bytes(int(y0 + r), &buf[r * stride]); });
        iovec pieces[2] = {{const_cast<char*>(header.data()), header.size()}, {buf.data(), rows * stride}};
        if (y0 == 0) sink(pieces);
        else sink(std::span<const iovec>(pieces + 1, 1));
    }
}

// PFM rows go bottom to top: handed to the sink straight from the framebuffer, no copy.
void encode_pfm(const Framebuffer& fb, const ByteSink& sink) {
    const std::string header = ppm_pfm_header("PF", fb, "-1.0");  // negative: little-endian
    std::vector<iovec> pieces;
    pieces.reserve(std::size_t(fb.height) + 1);
    pieces.push_back({const_cast<char*>(header.data()), header.size()});
    for (int y = fb.height - 1; y >= 0; --y)
        pieces.push_back({const_cast<float*>(fb.pixel(0, y)), std::size_t(fb.width) * 3 * sizeof(float)});
    sink(pieces);
}

void put_be32(unsigned char* p, std::uint32_t v) {
    p[0] = static_cast<unsigned char>(v >> 24);
    p[1] = static_cast<unsigned char>(v >> 16);
    p[2] = static_cast<unsigned char>(v >> 8);
    p[3] = static_cast<unsigned char>(v);
}

// A PNG chunk's framing around data given in pieces: length and type before, CRC after.
struct ChunkFrame {
    unsigned char head[8], crc[4];
    ChunkFrame(const char* type, std::initializer_list<std::span<const unsigned char>> data) {
        std::size_t length = 0;
        std::memcpy(head + 4, type, 4);
        uLong c = ::crc32(0, head + 4, 4);
        for (auto d : data) {
            length += d.size();
            c = ::crc32_z(c, d.data(), d.size());
        }
        put_be32(head, std::uint32_t(length));
        put_be32(crc, std::uint32_t(c));
    }
};

// One band of rows, filtered and deflated as a raw piece of the image's one zlib stream:
// the last band finishes the stream, the others end on a sync flush (byte-aligned, not
// final), so the pieces are independent and simply concatenate.
struct PngBand {
    std::vector<unsigned char> z;
    uLong adler = 1;
    std::size_t raw_bytes = 0;
};

void encode_png_band(const Framebuffer& fb, const EightBitRows& to_bytes, int y0, int y1, const PngOptions& o,
                     PngBand& band) {
    const std::size_t stride = std::size_t(fb.width) * 3;
    std::vector<unsigned char> rows(2 * stride), filtered(std::size_t(y1 - y0) * (stride + 1));
    unsigned char *prev = rows.data(), *cur = rows.data() + stride;
    // Up reads the row above, also across the band's top edge (it is in the framebuffer).
    if (y0 > 0 && o.filter == PngFilter::Up) to_bytes(y0 - 1, prev);
    else std::fill_n(prev, stride, 0);
    unsigned char* out = filtered.data();
    for (int y = y0; y < y1; ++y) {
        to_bytes(y, cur);
        *out++ = static_cast<unsigned char>(o.filter);
        if (o.filter == PngFilter::Up)
            for (std::size_t i = 0; i < stride; ++i) out[i] = static_cast<unsigned char>(cur[i] - prev[i]);
        else if (o.filter == PngFilter::Sub) {
            std::copy_n(cur, 3, out);
            for (std::size_t i = 3; i < stride; ++i) out[i] = static_cast<unsigned char>(cur[i] - cur[i - 3]);
        } else
            std::copy_n(cur, stride, out);
        out += stride;
        std::swap(prev, cur);
    }
    band.raw_bytes = filtered.size();
    band.adler = ::adler32_z(1, filtered.data(), filtered.size());
    z_stream z{};
    if (deflateInit2(&z, o.level, Z_DEFLATED, -15, 8, o.strategy) != Z_OK) throw std::bad_alloc();
    const bool last = y1 == fb.height;
    band.z.resize(deflateBound(&z, uLong(filtered.size())) + 16);  // + the sync flush's empty block
    z.next_in = filtered.data();
    z.avail_in = uInt(filtered.size());
    z.next_out = band.z.data();
    z.avail_out = uInt(band.z.size());
    const int rc = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
    const bool done = last ? rc == Z_STREAM_END : rc == Z_OK && z.avail_in == 0 && z.avail_out > 0;
    band.z.resize(band.z.size() - z.avail_out);
    deflateEnd(&z);
    if (!done) throw RenderError("PNG encoding failed (zlib " + std::to_string(rc) + ")");
}

void encode_png(const Framebuffer& fb, const EightBitRows& to_bytes, const ByteSink& sink, const WriteOptions& o) {
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char ihdr[13];
    put_be32(ihdr, std::uint32_t(fb.width));
    put_be32(ihdr + 4, std::uint32_t(fb.height));
    const unsigned char rest[5] = {8, 2, 0, 0, 0};  // 8-bit RGB, deflate, adaptive filters, no interlace
    std::memcpy(ihdr + 8, rest, 5);
    const ChunkFrame ihdr_frame("IHDR", {ihdr});
    static const unsigned char zlib_header[2] = {0x78, 0x01};  // deflate, 32 KiB window, check bits
    std::vector<iovec> pieces = {{const_cast<unsigned char*>(signature), 8},
                                 {const_cast<unsigned char*>(ihdr_frame.head), 8},
                                 {ihdr, 13},
                                 {const_cast<unsigned char*>(ihdr_frame.crc), 4}};
    const int band_rows = png_band_rows(fb.width);
    const std::size_t bands = (std::size_t(fb.height) + std::size_t(band_rows) - 1) / std::size_t(band_rows);
    std::vector<PngBand> group(std::min(bands, kPngBandsInFlight));
    std::vector<ChunkFrame> frames;
    frames.reserve(group.size());
    uLong adler = 1;
    unsigned char adler_be[4];
    for (std::size_t b0 = 0; b0 < bands; b0 += group.size()) {
        if (o.cancel && o.cancel->load()) throw Cancelled{};
        const std::size_t n = std::min(group.size(), bands - b0);
        for_each(o.par, n, 1, [&](std::size_t i) {
            const int y0 = int(b0 + i) * band_rows;
            encode_png_band(fb, to_bytes, y0, std::min(fb.height, y0 + band_rows), o.png, group[i]);
        });
        // One IDAT per band: the first carries the zlib header, the last the Adler-32.
        frames.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const PngBand& band = group[i];
            adler = ::adler32_combine(adler, band.adler, z_off_t(band.raw_bytes));
            const bool first = b0 + i == 0, last = b0 + i + 1 == bands;
            if (last) put_be32(adler_be, std::uint32_t(adler));
            const std::span<const unsigned char> head(zlib_header, first ? 2 : 0), tail(adler_be, last ? 4 : 0);
            frames.emplace_back("IDAT", std::initializer_list<std::span<const unsigned char>>{head, band.z, tail});
            pieces.push_back({frames.back().head, 8});
            if (first) pieces.push_back({const_cast<unsigned char*>(zlib_header), 2});
            pieces.push_back({const_cast<unsigned char*>(band.z.data()), band.z.size()});
            if (last) pieces.push_back({adler_be, 4});
            pieces.push_back({frames.back().crc, 4});
        }
        if (b0 + n == bands) {
            static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
            pieces.push_back({const_cast<unsigned char*>(iend), 12});
        }
        sink(pieces);
        pieces.clear();
    }
}

// Writes every piece, a few hundred at a time (writev), resuming after short writes.
void write_all(int fd, std::span<const iovec> pieces) {
    std::vector<iovec> rest(pieces.begin(), pieces.end());
    std::size_t i = 0;
    while (i < rest.size()) {
        if (rest[i].iov_len == 0) {
            ++i;
            continue;
        }
        const ssize_t n = ::writev(fd, &rest[i], int(std::min<std::size_t>(rest.size() - i, IOV_MAX)));
        if (n < 0) {
            if (errno == EINTR) continue;
            throw std::system_error(errno, std::generic_category());
        }
        for (std::size_t left = std::size_t(n); left > 0;) {
            const std::size_t take = std::min(left, rest[i].iov_len);
            rest[i].iov_base = static_cast<char*>(rest[i].iov_base) + take;
            rest[i].iov_len -= take;
            left -= take;
            if (rest[i].iov_len == 0) ++i;
        }
    }
}

}  // namespace

int png_band_rows(int width) {
    const std::size_t stride = std::size_t(std::max(width, 1)) * 3;
    return int(std::max<std::size_t>(1, (kPngBandBytes + stride - 1) / stride));
}

double image_write_buffer_bytes(int width, int height) {
    const double stride = double(width) * 3;
    // PNG: each band in flight holds two 8-bit rows, its filtered rows, their deflate bound
    // and a deflate state; all of them until the group is written.
    const int band_rows = png_band_rows(width);
    const double filtered = double(std::min(band_rows, height)) * (stride + 1);
    const double band = 2 * stride + filtered + (filtered + std::ceil(filtered / 1000) + 64) + kDeflateStateBytes;
    const std::size_t bands = (std::size_t(height) + std::size_t(band_rows) - 1) / std::size_t(band_rows);
    const double png = double(std::min(kPngBandsInFlight, bands)) * band;
    const double ppm = double(std::min(ppm_chunk_rows(width), std::size_t(height))) * stride;
    const double pfm = (double(height) + 1) * sizeof(iovec);
    return std::max({png, ppm, pfm, exr_write_buffer_bytes(width, height)});
}

bool encode_image(const Framebuffer& fb, ImageFormat format, const Display& display, const ByteSink& sink,
                  const WriteOptions& options) {
    if (fb.width <= 0 || fb.height <= 0) throw RenderError("cannot encode an empty image");
    if (format == ImageFormat::Exr) throw RenderError("EXR is written to files only (write_image)");
    try {
        // PFM keeps the linear values for error measurement; the 8-bit formats are for display.
        if (format == ImageFormat::Pfm) encode_pfm(fb, sink);
        else if (format == ImageFormat::Ppm) encode_ppm(fb, EightBitRows(fb, display, options.par), sink, options);
        else encode_png(fb, EightBitRows(fb, display, options.par), sink, options);
    } catch (const Cancelled&) {
        return false;
    }
    return true;
}

namespace {

/// Through a temporary name in the same folder (so the rename is atomic): fill(fd) writes
/// the content; whatever stops it (an error, bad_alloc, Ctrl-C: fill returns false) leaves no
/// temporary behind and no file at `path`. `cancel` is looked at once more after the last
/// byte: a Ctrl-C that arrives during the final write still leaves no file.
template <class Fill>
bool write_atomically(const std::string& path, const std::atomic<bool>* cancel, Fill&& fill) {
    const fs::path target(path);
    std::string tmp_name = ".";  // appended, not "." + ...: GCC 12 warns falsely on that
    tmp_name += target.filename().string() + ".tmp" + std::to_string(::getpid());
    const fs::path tmp = target.parent_path() / tmp_name;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw RenderError(path + ": cannot write: " + std::strerror(errno));
    bool written = false;
    try {
        written = fill(fd);
    } catch (const std::system_error& e) {
        ::close(fd);
        ::unlink(tmp.c_str());
        throw RenderError(path + ": write failed: " + std::strerror(e.code().value()));
    } catch (...) {
        ::close(fd);
        ::unlink(tmp.c_str());
        throw;
    }
    if (::close(fd) != 0 && written) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw RenderError(path + ": write failed: " + std::strerror(err));
    }
    if (!written || (cancel && cancel->load())) {
        ::unlink(tmp.c_str());
        return false;
    }
    if (std::rename(tmp.c_str(), target.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw RenderError(path + ": cannot rename into place: " + std::strerror(err));
    }
    return true;
}

}  // namespace

bool write_image(const std::string& path, const Framebuffer& fb, const Display& display,
                 const WriteOptions& options) {
    const auto format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format (expected .ppm, .png, .pfm or .exr)");
    if (*format == ImageFormat::Exr) {
        if (fb.width <= 0 || fb.height <= 0) throw RenderError("cannot encode an empty image");
        return write_atomically(path, options.cancel, [&](int fd) { return write_exr(fd, path, fb, display.exr, options); });
    }
    return write_atomically(path, options.cancel, [&](int fd) {
        return encode_image(fb, *format, display, [fd](std::span<const iovec> p) { write_all(fd, p); }, options);
    });
}

void write_text_file(const std::string& path, std::string_view text) {
    write_atomically(path, nullptr, [&](int fd) {
        const iovec piece{const_cast<char*>(text.data()), text.size()};
        write_all(fd, std::span<const iovec>(&piece, 1));
        return true;
    });
}

namespace {

std::string read_all(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw RenderError(path + ": cannot open");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Reads "P6"/"PF" header fields: whitespace-separated tokens, '#' comments.
struct HeaderReader {
    const std::string& data;
    std::size_t pos = 0;
    std::string token() {
        while (pos < data.size()) {
            if (data[pos] == '#') {
                while (pos < data.size() && data[pos] != '\n') ++pos;
            } else if (std::isspace(static_cast<unsigned char>(data[pos]))) {
                ++pos;
            } else {
                break;
            }
        }
        const std::size_t start = pos;
        while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
        return data.substr(start, pos - start);
    }
};

}  // namespace

Framebuffer read_image(const std::string& path) {
    const auto format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format");
    if (*format == ImageFormat::Exr) return read_exr(path);
    if (*format == ImageFormat::Png) {
        int w = 0, h = 0, n = 0;
        unsigned char* px = stbi_load(path.c_str(), &w, &h, &n, 3);
        if (!px) throw RenderError(path + ": cannot decode PNG");
        Framebuffer fb = Framebuffer::uninitialized(w, h);
        for (std::size_t i = 0; i < fb.rgb.size(); ++i) fb.rgb[i] = px[i] / 255.f;
        stbi_image_free(px);
        return fb;
    }
    const std::string data = read_all(path);
    HeaderReader r{data};
    const std::string magic = r.token();
    const int w = std::atoi(r.token().c_str()), h = std::atoi(r.token().c_str());
    const std::string third = r.token();
    ++r.pos;  // the single whitespace byte before the raster
    if (w <= 0 || h <= 0) throw RenderError(path + ": bad header");
    Framebuffer fb = Framebuffer::uninitialized(w, h);
    const std::size_t n = fb.rgb.size();
    if (*format == ImageFormat::Ppm) {
        if (magic != "P6" || third != "255" || data.size() < r.pos + n) throw RenderError(path + ": not a P6 PPM");
        for (std::size_t i = 0; i < n; ++i) fb.rgb[i] = static_cast<unsigned char>(data[r.pos + i]) / 255.f;
    } else {
        if (magic != "PF" || data.size() < r.pos + n * sizeof(float)) throw RenderError(path + ": not an RGB PFM");
        for (int y = 0; y < h; ++y)
            std::memcpy(fb.pixel(0, h - 1 - y), data.data() + r.pos + std::size_t(y) * w * 3 * sizeof(float),
                        std::size_t(w) * 3 * sizeof(float));
    }
    return fb;
}

}  // namespace streamrt
