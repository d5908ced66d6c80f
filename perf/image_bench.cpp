// Timing program for image output (docs/performance.md, "## Image output"). Not a test.
//
//   image_bench [SCENE [WIDTH HEIGHT [display]]]
//
// Renders SCENE (default scenes/whitted.cfg, 2560x1440, 1 spp) once, then times encoding
// its picture to PNG in memory, median of 5, with: the old pipeline (calibrated float copy,
// 8-bit copy, stb_image_write at its default level), stb at level 1 with and without a
// forced filter, libdeflate at level 1 on the whole image (one thread: it cannot cut a
// stream into independent pieces), and streamrt's banded zlib writer at several levels,
// strategies and filters on -j1 and -j2. Then PPM, PFM and the whole write_image to a file.
// With "display" (docs/performance.md, "## Display colour and EXR"): only the 8-bit
// conversion for each display setting (PPM in memory, the conversion is most of its cost),
// against a straightforward per-value pow, and EXR files, on -j1 and -j2.
#include <zlib.h>

#include <ctime>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#ifdef STREAMRT_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include "bench_clock.h"
#include "image/image_io.h"
#include "parallel/parallelism.h"
#include "driver/render.h"
#include "scene/parser.h"

using namespace streamrt;
using streamrt::perf::now;

namespace {

double cpu_now() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Median of 5 runs of f: wall and CPU (all threads) milliseconds, and the size f reports.
// CPU time is the steadier figure on a shared machine.
void report(const char* name, const std::function<std::size_t()>& f) {
    std::vector<double> wall, cpu;
    std::size_t bytes = 0;
    for (int i = 0; i < 5; ++i) {
        const double t0 = now(), c0 = cpu_now();
        bytes = f();
        wall.push_back((now() - t0) * 1e3);
        cpu.push_back((cpu_now() - c0) * 1e3);
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    std::printf("%-52s %7.1f ms wall %7.1f ms cpu %9zu bytes\n", name, wall[2], cpu[2], bytes);
}

// The pipeline before the streaming writer: calibrate(), an 8-bit copy with lround.
std::vector<unsigned char> old_bytes(const Framebuffer& fb) {
    const Framebuffer c = calibrate(fb, Calibration::Clamp);
    std::vector<unsigned char> b(c.rgb.size());
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<unsigned char>(std::lround(c.rgb[i] * 255.f));
    return b;
}

std::size_t stb_png(const Framebuffer& fb, int level, int filter) {
    stbi_write_png_compression_level = level;
    stbi_write_force_png_filter = filter;
    const auto b = old_bytes(fb);
    std::string out;
    stbi_write_png_to_func([](void* ctx, void* d, int n) { static_cast<std::string*>(ctx)->append((char*)d, n); },
                           &out, fb.width, fb.height, 3, b.data(), fb.width * 3);
    return out.size();
}

#ifdef STREAMRT_HAVE_LIBDEFLATE
// Up-filtered rows, then one libdeflate zlib stream (no PNG framing: the compressor alone).
std::size_t libdeflate_up(const Framebuffer& fb, int level) {
    const auto b = old_bytes(fb);
    const std::size_t stride = std::size_t(fb.width) * 3;
    std::vector<unsigned char> f(std::size_t(fb.height) * (stride + 1));
    for (int y = 0; y < fb.height; ++y) {
        unsigned char* o = &f[std::size_t(y) * (stride + 1)];
        const unsigned char* cur = &b[std::size_t(y) * stride];
        o[0] = 2;
        for (std::size_t i = 0; i < stride; ++i) o[1 + i] = static_cast<unsigned char>(cur[i] - (y ? cur[i - stride] : 0));
    }
    libdeflate_compressor* c = libdeflate_alloc_compressor(level);
    std::vector<unsigned char> out(libdeflate_zlib_compress_bound(c, f.size()));
    const std::size_t n = libdeflate_zlib_compress(c, f.data(), f.size(), out.data(), out.size());
    libdeflate_free_compressor(c);
    return n;
}
#endif

std::size_t streamrt_encode(const Framebuffer& fb, const ImageFormat& format, const Display& d, const WriteOptions& o) {
    std::size_t n = 0;
    encode_image(fb, format, d, [&](std::span<const iovec> p) {
        for (const iovec& v : p) n += v.iov_len;
    }, o);
    return n;
}

// The handout's linear output, as before the display colour keys.
std::size_t streamrt_encode(const Framebuffer& fb, const ImageFormat& format, const WriteOptions& o) {
    return streamrt_encode(fb, format, Display::raw(Calibration::Clamp), o);
}

// The straightforward sRGB conversion the table replaces: clamp, the IEC curve by pow, lround.
std::size_t pow_srgb_bytes(const Framebuffer& fb, std::vector<unsigned char>& out) {
    out.resize(fb.rgb.size());
    for (std::size_t i = 0; i < fb.rgb.size(); ++i) {
        const float v = fb.rgb[i];
        const double c = std::isfinite(v) ? std::clamp(double(v), 0.0, 1.0) : 0.0;
        out[i] = static_cast<unsigned char>(std::lround(255.0 * srgb_oetf(c)));
    }
    return out.size();
}

void display_rows(const Framebuffer& fb) {
    std::vector<unsigned char> bytes;
    report("straightforward pow sRGB + lround, 1 thread", [&] { return pow_srgb_bytes(fb, bytes); });
    for (int jobs : {1, 2}) {
        Parallelism par(jobs);
        WriteOptions o;
        o.par = &par;
        const std::string j = ", -j" + std::to_string(jobs);
        Display srgb, reinhard, normalize;
        reinhard.tonemap = Tonemap::Reinhard;
        normalize.tonemap = Tonemap::Reinhard;
        normalize.calibration = Calibration::Normalize;
        report(("PPM linear clamp (handout)" + j).c_str(), [&] { return streamrt_encode(fb, image_format(".ppm"), o); });
        report(("PPM srgb clamp (default)" + j).c_str(), [&] { return streamrt_encode(fb, image_format(".ppm"), srgb, o); });
        report(("PPM srgb reinhard" + j).c_str(), [&] { return streamrt_encode(fb, image_format(".ppm"), reinhard, o); });
        report(("PPM srgb reinhard normalize" + j).c_str(),
               [&] { return streamrt_encode(fb, image_format(".ppm"), normalize, o); });
        report(("PNG linear clamp (handout)" + j).c_str(), [&] { return streamrt_encode(fb, image_format(".png"), o); });
        report(("PNG srgb clamp (default)" + j).c_str(), [&] { return streamrt_encode(fb, image_format(".png"), srgb, o); });
        for (const ExrPixels px : {ExrPixels::Half, ExrPixels::Float}) {
            Display d;
            d.exr = px;
            report(((px == ExrPixels::Half ? "write_image .exr half" : "write_image .exr float") + j).c_str(), [&] {
                write_image("/tmp/streamrt_image_bench.exr", fb, d, o);
                return std::size_t(std::filesystem::file_size("/tmp/streamrt_image_bench.exr"));
            });
        }
    }
    std::remove("/tmp/streamrt_image_bench.exr");
}

}  // namespace

int main(int argc, char** argv) {
    Scene scene = load_scene(argc > 1 ? argv[1] : "scenes/whitted.cfg");
    scene.settings.width = argc > 3 ? std::atoi(argv[2]) : 2560;
    scene.settings.height = argc > 3 ? std::atoi(argv[3]) : 1440;
    scene.settings.spp = 1;
    Framebuffer fb;
    {
        Parallelism par(2);
        fb = render_scene(scene, EngineKind::Stream, par).image;
    }
    std::printf("%dx%d, median of 5\n", fb.width, fb.height);
    if (argc > 4 && std::string(argv[4]) == "display") {
        display_rows(fb);
        return 0;
    }
    report("old: calibrate + lround copy + stb level 8 (default)", [&] { return stb_png(fb, 8, -1); });
    report("stb level 1", [&] { return stb_png(fb, 1, -1); });
    report("stb level 1, filter Up forced", [&] { return stb_png(fb, 1, 2); });
#ifdef STREAMRT_HAVE_LIBDEFLATE
    report("libdeflate level 1, Up, whole image, 1 thread", [&] { return libdeflate_up(fb, 1); });
    report("libdeflate level 3, Up, whole image, 1 thread", [&] { return libdeflate_up(fb, 3); });
#endif
    struct Variant {
        const char* name;
        PngOptions png;
    };
    const Variant variants[] = {
        {"zlib 1 default, Up", {1, Z_DEFAULT_STRATEGY, PngFilter::Up}},
        {"zlib 1 default, Sub", {1, Z_DEFAULT_STRATEGY, PngFilter::Sub}},
        {"zlib 1 default, None", {1, Z_DEFAULT_STRATEGY, PngFilter::None}},
        {"zlib 6 default, Up", {6, Z_DEFAULT_STRATEGY, PngFilter::Up}},
        {"zlib RLE, Up", {1, Z_RLE, PngFilter::Up}},
        {"zlib RLE, Sub", {1, Z_RLE, PngFilter::Sub}},
        {"zlib RLE, None", {1, Z_RLE, PngFilter::None}},
        {"zlib Huffman only, Up", {1, Z_HUFFMAN_ONLY, PngFilter::Up}},
    };
    for (int jobs : {1, 2}) {
        Parallelism par(jobs);
        for (const Variant& v : variants) {
            WriteOptions o;
            o.par = &par;
            o.png = v.png;
            const std::string name = std::string("streamrt bands: ") + v.name + ", -j" + std::to_string(jobs);
            report(name.c_str(), [&] { return streamrt_encode(fb, image_format(".png"), o); });
        }
        WriteOptions o;
        o.par = &par;
        report(("streamrt PPM, -j" + std::to_string(jobs)).c_str(), [&] { return streamrt_encode(fb, image_format(".ppm"), o); });
        report(("streamrt PFM, -j" + std::to_string(jobs)).c_str(), [&] { return streamrt_encode(fb, image_format(".pfm"), o); });
        report(("write_image to /tmp .png (default), -j" + std::to_string(jobs)).c_str(), [&] {
            write_image("/tmp/streamrt_image_bench.png", fb, Display::raw(Calibration::Clamp), o);
            return std::size_t(0);
        });
    }
    std::remove("/tmp/streamrt_image_bench.png");
    return 0;
}
