#include "image/display.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "image/format_util.h"
#include "parallel/parallelism.h"

namespace streamrt {

using image_detail::for_each;

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
}  // namespace

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

namespace {

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

}  // namespace

EightBitRows::EightBitRows(const Framebuffer& fb, const Display& d, Parallelism* par) : fb_(fb) {
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

void EightBitRows::operator()(int y, unsigned char* out) const {
    if (row_) row_(fb_, y, pre_, post_, tables_, out);
    else row_to_bytes(fb_, y, pre_, out);
}

}  // namespace streamrt
