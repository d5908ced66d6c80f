// Gathered shading on meshes (stream/shade_stage.h, kernels/shade_kernel.h): hits regrouped by
// material and shape kind put the instances of several meshes, smooth and flat, into one run,
// and each lane reads its own object's mesh, smooth flag and texture coordinates; the picture
// is that of runs by object. Mesh scenes above kSortedShadeMaxObjects objects shade gathered.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "driver/render.h"
#include "image/image_compare.h"
#include "mesh/mesh.h"
#include "parallel/parallelism.h"
#include "scene/parser.h"
#include "stream/shade_stage.h"
#include "stream/stream_scene.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

/// A temporary folder with ball.obj (a level-2 icosphere, no texture coordinates) and
/// wave.obj (a wavy 8 x 8 grid with texture coordinates), removed at the end.
struct MeshFiles {
    fs::path dir = fs::temp_directory_path() / ("streamrt_gathered_mesh_" + std::to_string(::getpid()));
    MeshFiles() {
        fs::create_directories(dir);
        REQUIRE(write_obj((dir / "ball.obj").string(), icosphere(2)));
        std::ofstream f(dir / "wave.obj");
        constexpr int n = 8;
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) {
                const double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
                f << "v " << x << ' ' << y << ' ' << 0.25 * std::sin(3 * x) * std::cos(2 * y) << '\n';
            }
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) f << "vt " << 1.5 * i / n << ' ' << double(j) / n << '\n';
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 2, d = a + n + 1;
                f << "f " << a << '/' << a << ' ' << b << '/' << b << ' ' << c << '/' << c << '\n';
                f << "f " << a << '/' << a << ' ' << c << '/' << c << ' ' << d << '/' << d << '\n';
            }
    }
    ~MeshFiles() { fs::remove_all(dir); }
    std::string cfg() const { return (dir / "scene.cfg").string(); }
};

Framebuffer render_shaded(const Scene& s, Isa isa, ShadeMode shade) {
    Parallelism par(2);
    EngineOptions opt;
    opt.isa = isa;
    opt.shade = shade;
    return render_scene(s, EngineKind::Stream, par, nullptr, opt).image;
}

}  // namespace

TEST_CASE("gathered shading: mesh instances of several meshes, materials, smooth and flat, textured, give the picture of runs by object, every ISA") {
    const MeshFiles files;
    const std::string textures = std::string(STREAMRT_SOURCE_DIR) + "/scenes/textures/";
    // One run per (material, kind) when gathered: clay's meshes mix a smooth and a flat ball,
    // shiny's a smooth and a flat one with mirror children, tiles' two waves (smooth and flat)
    // and the banner, three objects of two meshes whose texture coordinates and uv densities
    // differ. Shadows on (the smooth lanes' terminator shift, the flat lanes' none).
    const std::string text = "image width=96 height=72 spp=2 degree=5 depth=2\n"
                             "camera eye=0,3,7 look=0,0.8,0\n"
                             "light point pos=3,6,4\n"
                             "light point pos=-4,5,3 color=0.5,0.5,0.5\n"
                             "material clay diff=0.8 spec=0.4 shininess=40\n"
                             "material shiny diff=0.6 spec=0.6 shininess=80 refl=0.3\n"
                             "material tiles texture=" + textures + "tiles.png ambi=1 diff=0.9 spec=0.2\n"
                             "plane color=0.5,0.5,0.5 checker=0.2,0.2,0.2\n"
                             "mesh file=ball.obj smooth=true material=clay color=0.9,0.5,0.3 translate=-2,1,0\n"
                             "mesh file=ball.obj smooth=false material=clay color=0.4,0.8,0.3 scale=0.8 translate=0,0.8,0\n"
                             "sphere material=clay color=0.9,0.9,0.3 scale=0.4 translate=-1,0.4,2\n"
                             "mesh file=ball.obj smooth=true material=shiny color=0.3,0.5,0.9 scale=0.6 translate=1,0.6,1.8\n"
                             "mesh file=ball.obj material=shiny color=0.8,0.3,0.8 scale=0.6 translate=-3,0.6,1.5\n"
                             "mesh file=wave.obj smooth=true material=tiles rotate_x=-60 translate=-2,1.5,-2\n"
                             "mesh file=wave.obj material=tiles rotate_x=-60 translate=0.3,1.5,-2.5\n"
                             "mesh file=" + textures + "banner.obj material=tiles scale=0.8 translate=2.2,1.8,-2\n";
    const Scene s = parse_scene(text, files.cfg());
    REQUIRE(s.objects.size() == 9);
    {
        const StreamScene sc(s);
        CHECK(sc.has_meshes);
        CHECK(resolve_shade_mode(sc, ShadeMode::Gathered) == ShadeMode::Gathered);
    }
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const std::string isa_str = isa_name(isa);
        CAPTURE(isa_str);
        const Framebuffer sorted = render_shaded(s, isa, ShadeMode::Sorted);
        const Framebuffer gathered = render_shaded(s, isa, ShadeMode::Gathered);
        // As for the scenes under scenes/ (stream_engine_test.cpp): the same arithmetic per
        // lane, only the order of a pixel's sums differs.
        const ImageDifference d = compare_images(gathered, sorted);
        MESSAGE(isa_str << ": gathered vs sorted max " << d.max_abs);
        CAPTURE(d.max_abs);
        CHECK(d.max_abs <= 1e-5);
        // The scalar path (shade_hit one ray at a time, with mesh_normal, mesh_texture_color
        // and smooth_corners) agrees within the same summation-order bound.
        const ImageDifference ds = compare_images(render_shaded(s, isa, ShadeMode::Scalar), gathered);
        CAPTURE(ds.max_abs);
        CHECK(ds.max_abs <= 1e-5);
    }
}

TEST_CASE("gathered shading: a mesh scene above kSortedShadeMaxObjects objects shades gathered, with the sorted picture") {
    const MeshFiles files;
    // A grid of small instances of one mesh, two materials, smooth and flat in turn; one more
    // than kSortedShadeMaxObjects, then exactly that many.
    const auto scene_of = [&](std::size_t count) {
        std::ostringstream t;
        t << "image width=64 height=48 spp=1 degree=5 depth=1\n"
             "camera eye=0,40,60 look=0,0,0\n"
             "light point pos=30,60,40\n"
             "material clay diff=0.8 spec=0.3 shininess=30\n"
             "material shiny diff=0.5 spec=0.6 shininess=80 refl=0.3\n";
        const int side = int(std::ceil(std::sqrt(double(count))));
        for (std::size_t k = 0; k < count; ++k) {
            const double x = (double(k % std::size_t(side)) - side / 2.0) * 0.8;
            const double z = (double(k / std::size_t(side)) - side / 2.0) * 0.8;
            t << "mesh file=ball.obj scale=0.35 material=" << (k % 3 == 0 ? "shiny" : "clay")
              << " smooth=" << (k % 2 == 0 ? "true" : "false") << " color=" << 0.3 + 0.6 * double(k % 7) / 6 << ",0.5,"
              << 0.9 - 0.6 * double(k % 5) / 4 << " translate=" << x << ",0.35," << z << '\n';
        }
        return parse_scene(t.str(), files.cfg());
    };
    const Scene big = scene_of(kSortedShadeMaxObjects + 1);
    {
        const StreamScene sc(big);
        REQUIRE(sc.object_count == kSortedShadeMaxObjects + 1);
        CHECK(resolve_shade_mode(sc, ShadeMode::Auto) == ShadeMode::Gathered);
    }
    {
        const StreamScene sc(scene_of(kSortedShadeMaxObjects));
        CHECK(resolve_shade_mode(sc, ShadeMode::Auto) == ShadeMode::Sorted);
    }
    const Framebuffer sorted = render_shaded(big, best_isa(), ShadeMode::Sorted);
    const Framebuffer automatic = render_shaded(big, best_isa(), ShadeMode::Auto);
    const ImageDifference d = compare_images(automatic, sorted);
    CAPTURE(d.max_abs);
    CHECK(d.max_abs <= 1e-5);
}
