// End to end: every example scene rendered by the stream engine and by the recursive
// baseline at reduced size, compared; determinism across thread counts, runs and ISA levels.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "image/image_compare.h"
#include "image_bits.h"
#include "kernels/kernel_table.h"
#include "parallel/parallelism.h"
#include "driver/render.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

// The bound once caught three real problems, fixed where they arose rather than loosened:
// shadow acne on the cone (its discriminant cancelled in float; cone_math.h now solves from a
// shifted origin), and float/double disagreement on the aliased far checker floor of
// degree0.cfg and whitted.cfg (the checker is now filtered over the ray's footprint).
constexpr int kWidth = 160, kHeight = 120, kSpp = 2;
constexpr double kMinPsnr = 50.0;         // dB
constexpr double kMaxShareOver = 0.001;   // share of pixels off by more than 1/255

std::vector<fs::path> scene_files() {
    std::vector<fs::path> v;
    // scenes/stress/ holds the stiff cases of docs/stability.md, each with its own stated
    // bounds, asserted by tests/stress/stress_test.cpp.
    const fs::path stress = fs::path(STREAMRT_SOURCE_DIR) / "scenes" / "stress";
    for (const auto& e : fs::recursive_directory_iterator(fs::path(STREAMRT_SOURCE_DIR) / "scenes"))
        if (e.is_regular_file() && e.path().extension() == ".cfg" && e.path().parent_path() != stress)
            v.push_back(e.path());
    std::sort(v.begin(), v.end());
    return v;
}

/// Files some other scene includes (fragments such as scenes/degrees/common.cfg).
std::set<fs::path> included_files(const std::vector<fs::path>& files) {
    std::set<fs::path> inc;
    for (const fs::path& f : files) {
        std::ifstream in(f);
        std::string line;
        while (std::getline(in, line)) {
            std::istringstream words(line);
            std::string w, arg;
            if (words >> w && w == "include" && words >> arg)
                inc.insert(fs::weakly_canonical(f.parent_path() / arg));
        }
    }
    return inc;
}

struct LoadedScene {
    std::string name;
    Scene scene;
};

/// Every scene under scenes/, at reduced size. Only include fragments may fail to load.
const std::vector<LoadedScene>& loaded_scenes() {
    static const std::vector<LoadedScene> scenes = [] {
        std::vector<LoadedScene> v;
        const auto files = scene_files();
        const auto fragments = included_files(files);
        for (const fs::path& f : files) {
            const std::string name = fs::relative(f, fs::path(STREAMRT_SOURCE_DIR)).string();
            try {
                Scene s = load_scene(f.string());
                s.settings.width = kWidth;
                s.settings.height = kHeight;
                s.settings.spp = kSpp;
                v.push_back({name, std::move(s)});
            } catch (const SceneError& e) {
                if (fragments.count(fs::weakly_canonical(f))) {
                    MESSAGE("skipping include fragment " << name << ": " << e.what());
                } else {
                    FAIL_CHECK("scene " << name << " does not load: " << e.what());
                }
            }
        }
        return v;
    }();
    return scenes;
}

Framebuffer render_with(const Scene& s, EngineKind engine, int jobs, Isa isa = best_isa(),
                        ShadeMode shade = ShadeMode::Auto) {
    Parallelism par(jobs);
    EngineOptions opt;
    opt.isa = isa;
    opt.shade = shade;
    return render_scene(s, engine, par, nullptr, opt).image;
}

/// The worst pixels of `a` against `b`, for the failure message.
std::string worst_pixels(const Framebuffer& a, const Framebuffer& b, int n = 8) {
    struct P {
        double err;
        int x, y;
    };
    std::vector<P> all;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            double e = 0;
            for (int c = 0; c < 3; ++c)
                e = std::max(e, std::abs(std::clamp(double(a.pixel(x, y)[c]), 0.0, 1.0) - std::clamp(double(b.pixel(x, y)[c]), 0.0, 1.0)));
            all.push_back({e, x, y});
        }
    std::partial_sort(all.begin(), all.begin() + std::min<std::ptrdiff_t>(n, std::ptrdiff_t(all.size())), all.end(),
                      [](const P& p, const P& q) { return p.err > q.err; });
    std::ostringstream s;
    s.precision(5);
    for (int i = 0; i < n && i < int(all.size()); ++i) {
        const P& p = all[std::size_t(i)];
        const float* pa = a.pixel(p.x, p.y);
        const float* pb = b.pixel(p.x, p.y);
        s << "\n  (" << p.x << "," << p.y << ") err " << p.err << " stream " << pa[0] << "," << pa[1] << "," << pa[2]
          << " recursive " << pb[0] << "," << pb[1] << "," << pb[2];
    }
    return s.str();
}

/// Calls f(scene, isa) for every scene under scenes/ and every ISA level this CPU has.
template <class F>
void for_each_scene_and_isa(F&& f) {
    for (const auto& ls : loaded_scenes()) {
        CAPTURE(ls.name);
        for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
            if (!isa_supported(isa)) continue;
            const std::string isa_str = isa_name(isa);
            CAPTURE(isa_str);
            f(ls, isa);
        }
    }
}

}  // namespace

TEST_CASE("stream engine: every scene under scenes/ loads (or is an include fragment)") {
    const auto files = scene_files();
    CHECK(files.size() >= 5);
    CHECK(loaded_scenes().size() >= files.size() - included_files(files).size());
    for (const auto& s : loaded_scenes()) MESSAGE("scene " << s.name << ": " << s.scene.objects.size() << " objects");
}

TEST_CASE("stream engine: matches the recursive baseline on every scene") {
    for (const auto& ls : loaded_scenes()) {
        CAPTURE(ls.name);
        const Framebuffer stream = render_with(ls.scene, EngineKind::Stream, 2);
        const Framebuffer recursive = render_with(ls.scene, EngineKind::Recursive, 2);
        REQUIRE(stream.width == kWidth);
        REQUIRE(stream.height == kHeight);
        const ImageDifference d = compare_images(stream, recursive);
        MESSAGE(ls.name << ": PSNR " << d.psnr << " dB, max " << d.max_abs << ", pixels over 1/255 " << d.share_over * 100
                        << "%");
        CAPTURE(d.psnr);
        CAPTURE(d.share_over);
        CAPTURE(d.max_abs);
        if (d.psnr < kMinPsnr || d.share_over > kMaxShareOver) MESSAGE("worst pixels of " << ls.name << worst_pixels(stream, recursive));
        CHECK(d.psnr >= kMinPsnr);
        CHECK(d.share_over <= kMaxShareOver);
    }
}

TEST_CASE("stream engine: bit-identical for -j1, -j2 and -j3 and for a thread with another scene's history, both engines") {
    // Tiles are handed out dynamically (parallel/parallelism.h): at -j1 one thread runs them in
    // index order; at -j2 and -j3 (3 threads on this 2-core machine: oversubscribed) each
    // thread runs a different, run-dependent subset in a different order, after different
    // predecessors in its thread-local workspace. A fourth schedule: -j1 on a thread that has
    // just rendered another scene (other size, spp and features), so every buffer the engine
    // keeps per thread starts from that scene's leftovers instead of from the tile before.
    // Every schedule must give the -j1 picture bit for bit.
    const auto& scenes = loaded_scenes();
    REQUIRE(scenes.size() >= 2);
    for (std::size_t k = 0; k < scenes.size(); ++k) {
        const auto& ls = scenes[k];
        CAPTURE(ls.name);
        const Scene& other = scenes[(k + 1) % scenes.size()].scene;
        for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
            const std::string engine_str = engine_name(engine);
            CAPTURE(engine_str);
            Framebuffer j1, after_other;
            // Fresh threads each time (the engines' per-thread buffers start empty).
            std::thread([&] { j1 = render_with(ls.scene, engine, 1); }).join();
            std::thread([&] {
                Scene warm = other;
                warm.settings.width = 37;  // tiles cut at other places, a partial last chunk
                warm.settings.height = 23;
                warm.settings.spp = 3;
                (void)render_with(warm, engine, 1);
                after_other = render_with(ls.scene, engine, 1);
            }).join();
            const Framebuffer j2 = render_with(ls.scene, engine, 2);
            const Framebuffer j3 = render_with(ls.scene, engine, 3);
            CHECK(bit_identical(j1, j2));
            CHECK(bit_identical(j1, j3));
            CHECK(bit_identical(j1, after_other));
        }
    }
}

TEST_CASE("stream engine: every supported ISA level gives the default picture") {
    for (const auto& ls : loaded_scenes()) {
        CAPTURE(ls.name);
        const Framebuffer def = render_with(ls.scene, EngineKind::Stream, 2);
        for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
            if (!isa_supported(isa)) continue;
            const std::string isa_str = isa_name(isa);
            CAPTURE(isa_str);
            const Framebuffer img = render_with(ls.scene, EngineKind::Stream, 2, isa);
            const ImageDifference d = compare_images(img, def);
            CAPTURE(d.psnr);
            CAPTURE(d.share_over);
            if (d.psnr < kMinPsnr || d.share_over > kMaxShareOver) MESSAGE("worst pixels" << worst_pixels(img, def));
            CHECK(d.psnr >= kMinPsnr);
            CHECK(d.share_over <= kMaxShareOver);
            if (isa == best_isa()) CHECK(bit_identical(img, def));
        }
    }
}

TEST_CASE("stream engine: hits regrouped by material and kind (gathered) give the picture of runs by object, every ISA") {
    // Per lane the gathered kernel does the same arithmetic on the same values as a run of one
    // object; only the order in which a pixel's contributions are summed differs. A pixel sums
    // at most a few dozen terms below 1 in float: rounding differences stay under 1e-5.
    for_each_scene_and_isa([](const LoadedScene& ls, Isa isa) {
        const Framebuffer sorted = render_with(ls.scene, EngineKind::Stream, 2, isa, ShadeMode::Sorted);
        const Framebuffer gathered = render_with(ls.scene, EngineKind::Stream, 2, isa, ShadeMode::Gathered);
        const ImageDifference d = compare_images(gathered, sorted);
        CAPTURE(d.max_abs);
        CHECK(d.max_abs <= 1e-5);
    });
}

TEST_CASE("stream engine: the scalar shade path gives the picture of the SIMD path on every scene, every ISA") {
    // Both paths run render/shading.h's shade_hit on the same arithmetic; the bound on the
    // share of pixels and the PSNR are those the engines are held to against each other, the
    // largest difference is held to the summation-order rounding measured below.
    for_each_scene_and_isa([](const LoadedScene& ls, Isa isa) {
        const Framebuffer simd = render_with(ls.scene, EngineKind::Stream, 2, isa, ShadeMode::Sorted);
        const Framebuffer scalar = render_with(ls.scene, EngineKind::Stream, 2, isa, ShadeMode::Scalar);
        const ImageDifference d = compare_images(scalar, simd);
        MESSAGE(ls.name << " " << isa_name(isa) << ": scalar vs SIMD shade max " << d.max_abs << ", over 1/255 "
                        << d.share_over * 100 << "%");
        CAPTURE(d.max_abs);
        CAPTURE(d.share_over);
        // The arithmetic is the same at every level (unfused multiply-adds, one pow rounding):
        // what is left is the order of a pixel's sums. Measured (160x120, 2 spp): at most
        // 1.19e-7, one float ulp at 1, on 28 of 48 scene x level pairs. Area lights add
        // spp x samples shadow terms per pixel, each rounded into the pixel's sum (below 1) in
        // an order that depends on the path: at most half an ulp, 2^-24, per term between
        // the two orders (scenes/soft_shadows.cfg: 64 terms, bound 3.8e-6, measured 4.2e-7).
        double area_terms = 0;
        for (const Light& l : ls.scene.lights)
            if (l.is_area()) area_terms += double(l.samples) * ls.scene.settings.spp;
        CHECK(d.max_abs <= std::max(1.2e-7, area_terms * 0x1p-24));
        CHECK(d.psnr >= kMinPsnr);
        CHECK(d.share_over <= kMaxShareOver);
    });
}
