// Texture lookups (render/texture.h): bilinear values, the mip chain and the mip level of a
// footprint, worked by hand on tiny textures; and a rendered pixel of a textured plane in
// both engines.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "render/texture.h"
#include "render/one_pixel.h"
#include "scene/parser.h"
#include "scene/test_png.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

/// The 2 x 2 texture in linear values: top row red, green; bottom row blue, white.
std::shared_ptr<const Texture> quad() {
    return Texture::build("quad", 2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1});
}

void check_color(const ColorT<double>& c, double r, double g, double b) {
    CHECK(c.x == doctest::Approx(r).epsilon(1e-6));
    CHECK(c.y == doctest::Approx(g).epsilon(1e-6));
    CHECK(c.z == doctest::Approx(b).epsilon(1e-6));
}

}  // namespace

// Proven against: v not flipped (row 0 at v = 0): the (0.25, 0.75) lookup gave blue;
// the wrap of x0 = -1 to the last column removed (clamped to 0): u = 0 gave red.
TEST_CASE("texture: bilinear lookups of a 2 x 2 texture at hand-worked coordinates") {
    const auto t = quad();
    const TextureLevelView& l0 = t->levels[0];
    // Texel centres: u = (i + 0.5) / 2, v = 1 - (j + 0.5) / 2.
    check_color(texture_bilinear(l0, 0.25, 0.75), 1, 0, 0);  // top-left texel
    check_color(texture_bilinear(l0, 0.75, 0.75), 0, 1, 0);  // top-right
    check_color(texture_bilinear(l0, 0.25, 0.25), 0, 0, 1);  // bottom-left
    check_color(texture_bilinear(l0, 0.5, 0.5), 0.5, 0.5, 0.5);  // the four, equally
    // x = 0.375 * 2 - 0.5 = 0.25: 3/4 red + 1/4 green.
    check_color(texture_bilinear(l0, 0.375, 0.75), 0.75, 0.25, 0);
    // y = (1 - 0.625) * 2 - 0.5 = 0.25: 3/4 red + 1/4 blue.
    check_color(texture_bilinear(l0, 0.25, 0.625), 0.75, 0, 0.25);
    // u = 0 is halfway between the last column and the first (repeat): red and green.
    check_color(texture_bilinear(l0, 0.0, 0.75), 0.5, 0.5, 0);
    // Repeated outside [0, 1): u = 1.25 and u = -0.75 are u = 0.25.
    check_color(texture_bilinear(l0, 1.25, 0.75), 1, 0, 0);
    check_color(texture_bilinear(l0, -0.75, -0.25), 1, 0, 0);
    // Float gives the same values.
    const ColorT<float> f = texture_bilinear(l0, 0.375f, 0.75f);
    CHECK(f.x == doctest::Approx(0.75));
    CHECK(f.y == doctest::Approx(0.25));
}

// Proven against: the odd last column not folded in (x1 = min(2x + 1, w - 1)): the 3 x 1
// level 1 was (0 + 3) / 2 = 1.5.
TEST_CASE("texture: the mip chain is the box-filtered mean, down to 1 x 1") {
    const auto t = quad();
    REQUIRE(t->levels.size() == 2);
    CHECK(t->levels[1].width == 1);
    CHECK(t->levels[1].height == 1);
    CHECK(t->levels[1].rgb[0] == doctest::Approx(0.5));
    CHECK(t->levels[1].rgb[1] == doctest::Approx(0.5));
    CHECK(t->levels[1].rgb[2] == doctest::Approx(0.5));
    // 3 x 1 (grey values 0, 3, 6): level 1 is 1 x 1, the odd column folded in: (0 + 3 + 6) / 3.
    const auto odd = Texture::build("odd", 3, 1, {0, 0, 0, 3, 3, 3, 6, 6, 6});
    REQUIRE(odd->levels.size() == 2);
    CHECK(odd->levels[1].width == 1);
    CHECK(odd->levels[1].rgb[0] == doctest::Approx(3.0));
}

// Proven against: the nearest lower level instead of the blend of two (f = 0 in
// texture_sample: the halfway lookup gave red); v not flipped (the red texel's centre read blue).
TEST_CASE("texture: the mip level of a footprint") {
    const auto t = Texture::build("grey", 4, 4, std::vector<float>(4 * 4 * 3, 0.5f));  // levels 4, 2, 1
    const TextureView v = t->view();
    CHECK(texture_lod(v, 0.5) == 0.0);   // under a texel: the finest
    CHECK(texture_lod(v, 1.0) == 0.0);
    CHECK(texture_lod(v, 2.0) == doctest::Approx(1.0));
    CHECK(texture_lod(v, 2.8284271247461903) == doctest::Approx(1.5));
    CHECK(texture_lod(v, 4.0) == doctest::Approx(2.0));
    CHECK(texture_lod(v, 1000.0) == doctest::Approx(2.0));  // at most the coarsest
    // Trilinear: halfway between level 0 (red at the top-left centre) and level 1 (grey 0.5).
    const auto q = quad();
    check_color(texture_sample(q->view(), 0.25, 0.75, 1.4142135623730951), 0.75, 0.25, 0.25);
    check_color(texture_sample(q->view(), 0.25, 0.75, 2.0), 0.5, 0.5, 0.5);
    // canonical_per_world: Md = scale 2 -> Mi = scale 1/2, det 1/8, cube root 1/2.
    const double mi[12] = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0};
    CHECK(canonical_per_world<double>(mi) == doctest::Approx(0.5));
    // Footprint 1 world unit on a plane placed by scale 2, 4-texel image, uvscale 1:
    // 1 x 0.5 (canonical per world) x 1 (plane uv density) x 4 = 2 texels: level 1.
    // A sphere's density 1/pi makes it 2/pi texels: level 0.
    MaterialT<double> m = MaterialT<double>::from(Material{});
    m.texture = v;
    const double s = canonical_per_world<double>(mi);
    const auto plane = texture_color(m, ShapeKind::Plane, Vec3d{0.1, 0, 0.1}, 0.0, s, 1.0);
    check_color(plane, 0.5, 0.5, 0.5);
    MaterialT<double> mq = MaterialT<double>::from(Material{});
    mq.texture = q->view();
    // Plane at canonical (0.25, 0, 0.75): (u, v) = (0.25, 0.75), the red texel's centre; a
    // footprint of 2 world units is 2 x 0.5 x 1 x 2 = 2 texels: level 1 (grey), 1/2: level 0.
    check_color(texture_color(mq, ShapeKind::Plane, Vec3d{0.25, 0, 0.75}, 0.0, s, 2.0), 0.5, 0.5, 0.5);
    check_color(texture_color(mq, ShapeKind::Plane, Vec3d{0.25, 0, 0.75}, 0.0, s, 0.5), 1, 0, 0);
}

// Proven against: the stream engine's texture branch removed from the SIMD shade kernel (the
// pixel stayed the object's colour, white); v not flipped in the lookup (blue, not red).
TEST_CASE("texture: a rendered pixel of a textured plane, both engines") {
    const fs::path dir = fs::temp_directory_path() / ("streamrt_texture_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    test::write_png((dir / "quad.png").string(), 2, 2, test::kQuad);
    // Looking straight down at the world origin with a tiny field of view (a footprint far
    // below a texel); the plane is moved by (-0.25, 0, 0.25), so the hit is canonical
    // (0.25, 0, -0.25): (u, v) = (0.25, -0.25), repeated to (0.25, 0.75), the centre of the
    // top-left (red) texel. Degree 0 shows the surface colour itself: red, exactly.
    const std::string head =
        "image width=1 height=1 spp=1 depth=0 degree=0\n"
        "camera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=0.01\n";
    test::check_one_pixel(
        parse_scene(head + "plane color=1,1,1 texture=quad.png translate=-0.25,0,0.25\n", (dir / "p.cfg").string()),
        1, 0, 0);
    // uvscale=2: (u, v) = (0.5, -0.5) -> (0.5, 0.5), the corner of all four texels: their mean.
    test::check_one_pixel(parse_scene(head + "plane texture=quad.png uvscale=2 translate=-0.25,0,0.25\n",
                                      (dir / "p.cfg").string()),
                          0.5, 0.5, 0.5);
    // Far away (fov 60: the pixel spans ~5.8 units, ~12 texels): the coarsest level, grey.
    test::check_one_pixel(parse_scene("image width=1 height=1 spp=1 depth=0 degree=0\n"
                                      "camera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=60\n"
                                      "plane texture=quad.png translate=-0.25,0,0.25\n",
                                      (dir / "p.cfg").string()),
                          0.5, 0.5, 0.5);
    fs::remove_all(dir);
}
