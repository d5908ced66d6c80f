// Constructive solid geometry traced by the recursive engine (render/csg_spans.h): hits at
// points worked out by hand, normals facing out of the result, shadow rays, and set identities
// that must hold pixel for pixel.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "baseline/recursive_renderer.h"
#include "driver/render.h"
#include "render/csg_spans.h"
#include "shapes/sphere_math.h"
#include "scene/parser.h"
#include "csg_cases.h"

using namespace streamrt;
using namespace streamrt::csg_cases;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Scene parse(const std::string& text) { return parse_scene(text, "t.cfg"); }


void check_vec(const Vec3d& v, double x, double y, double z) {
    CHECK(v.x == doctest::Approx(x).epsilon(1e-9));
    CHECK(v.y == doctest::Approx(y).epsilon(1e-9));
    CHECK(v.z == doctest::Approx(z).epsilon(1e-9));
}

}  // namespace

TEST_CASE("csg: a ray along a lens's axis meets the two caps at their vertices") {
    const Scene s = parse(kLens);
    HitD in, out;
    REQUIRE(hit_of(s, {0, 0, 10}, {0, 0, -1}, in));
    CHECK(in.t == doctest::Approx(9.5).epsilon(1e-12));
    check_vec(in.point, 0, 0, 0.5);
    check_vec(in.normal, 0, 0, 1);  // the cap of the sphere centred at z = -1.5
    REQUIRE(hit_of(s, {0, 0, 10}, {0, 0, -1}, out, in.t + 1e-9));
    CHECK(out.t == doctest::Approx(10.5).epsilon(1e-12));
    check_vec(out.normal, 0, 0, -1);  // leaving: the outward normal points along the ray
    CHECK(!hit_of(s, {0, 0, 10}, {0, 0, -1}, out, out.t + 1e-9));
}

TEST_CASE("csg: a ray parallel to a lens's axis meets the caps where the spheres say") {
    const Scene s = parse(kLens);
    const double z = std::sqrt(3.0) - 1.5;
    HitD in, out;
    REQUIRE(hit_of(s, {1, 0, 10}, {0, 0, -1}, in));
    CHECK(in.t == doctest::Approx(10 - z).epsilon(1e-12));
    check_vec(in.point, 1, 0, z);
    check_vec(in.normal, 0.5, 0, std::sqrt(3.0) / 2);  // from the centre (0, 0, -1.5), radius 2
    REQUIRE(hit_of(s, {1, 0, 10}, {0, 0, -1}, out, in.t + 1e-9));
    check_vec(out.point, 1, 0, -z);
    check_vec(out.normal, 0.5, 0, -std::sqrt(3.0) / 2);
    // Beyond the rim (|x| > sqrt(4 - 1.5^2) = 1.3229) the spheres do not overlap.
    CHECK(!hit_of(s, {1.33, 0, 10}, {0, 0, -1}, in));
}

TEST_CASE("csg: along two overlapping spheres' axis a union meets all four surfaces, a merge the outer two") {
    // (x of the point, x of the normal shown, the shape) of each surface from x = -5 along +x.
    using Surface = std::tuple<double, double, int>;
    const auto surfaces = [](const std::string& op) {
        const Scene s = parse("csg " + op + "\n" + kTwoSpheres + "end\n");
        std::vector<Surface> seen;
        HitD h;
        for (double t_min = 0; seen.size() < 8 && hit_of(s, {-5, 0, 0}, {1, 0, 0}, h, t_min); t_min = h.t + 1e-9) {
            CHECK(h.point.y == 0.0);
            CHECK(h.normal.y == doctest::Approx(0.0));
            seen.emplace_back(h.point.x, h.normal.x, int(std::size_t(h.object) - s.objects.size()));
        }
        return seen;
    };
    const std::vector<Surface> uni = surfaces("union"), merged = surfaces("merge");
    // Into the first sphere, into the second (inside the first), out of the first, out of the
    // second: each normal the outward one of its own sphere.
    const std::vector<Surface> four{{-1.5, -1, 0}, {-0.5, -1, 1}, {0.5, 1, 0}, {1.5, 1, 1}};
    const std::vector<Surface> two{{-1.5, -1, 0}, {1.5, 1, 1}};
    REQUIRE(uni.size() == four.size());
    REQUIRE(merged.size() == two.size());
    for (std::size_t i = 0; i < four.size(); ++i) {
        CAPTURE(i);
        CHECK(std::get<0>(uni[i]) == doctest::Approx(std::get<0>(four[i])).epsilon(1e-12));
        CHECK(std::get<1>(uni[i]) == doctest::Approx(std::get<1>(four[i])).epsilon(1e-12));
        CHECK(std::get<2>(uni[i]) == std::get<2>(four[i]));
    }
    for (std::size_t i = 0; i < two.size(); ++i) {
        CHECK(std::get<0>(merged[i]) == doctest::Approx(std::get<0>(two[i])).epsilon(1e-12));
        CHECK(std::get<1>(merged[i]) == doctest::Approx(std::get<1>(two[i])).epsilon(1e-12));
        CHECK(std::get<2>(merged[i]) == std::get<2>(two[i]));
    }
}

TEST_CASE("csg: a torus is a solid: along the ring's diameter, its four surfaces and the bite's two") {
    const Scene s = parse(kRingCut);
    // (x, x of the normal shown, the shape): into the tube, out at its inner equator (the
    // normal towards the ring's centre), in again, out into the bite (the sphere's surface
    // turned round), back out of the bite, out of the tube.
    const std::vector<std::tuple<double, double, int>> want{{-1.5, -1, 0}, {-0.5, 1, 0}, {0.5, -1, 0},
                                                            {0.7, 1, 1},   {1.3, -1, 1}, {1.5, 1, 0}};
    std::size_t n = 0;
    HitD h;
    for (double t_min = 0; n < 8 && hit_of(s, {-5, 0, 0}, {1, 0, 0}, h, t_min); t_min = h.t + 1e-9, ++n) {
        REQUIRE(n < want.size());
        CAPTURE(n);
        CHECK(h.point.x == doctest::Approx(std::get<0>(want[n])).epsilon(1e-12));
        CHECK(h.normal.x == doctest::Approx(std::get<1>(want[n])).epsilon(1e-9));
        CHECK(int(std::size_t(h.object) - s.objects.size()) == std::get<2>(want[n]));
    }
    CHECK(n == want.size());
    // Down the ring's axis, through the hole: nothing.
    CHECK(!hit_of(s, {0, 5, 0}, {0, -1, 0}, h));
}

TEST_CASE("csg: a ray through a pipe's hole hits nothing, and its walls face out of the pipe") {
    const Scene s = parse(kPipe);
    HitD hit;
    CHECK(!hit_of(s, {0, 10, 0}, {0, -1, 0}, hit));
    CHECK(!hit_of(s, {0.3, 10, 0.3}, {0, -1, 0}, hit));
    // Down onto the rim's annulus at x = 0.9: the outer cylinder's top cap at y = 2.
    REQUIRE(hit_of(s, {0.9, 10, 0}, {0, -1, 0}, hit));
    CHECK(hit.t == doctest::Approx(8.0).epsilon(1e-12));
    check_vec(hit.normal, 0, 1, 0);
    // Across the pipe: into the outer wall at x = -1, out of the material at the inner wall
    // x = -0.8, whose normal (the removed cylinder's, turned round) points into the hole.
    REQUIRE(hit_of(s, {-5, 0, 0}, {1, 0, 0}, hit));
    CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
    check_vec(hit.normal, -1, 0, 0);
    REQUIRE(hit_of(s, {-5, 0, 0}, {1, 0, 0}, hit, hit.t + 1e-9));
    CHECK(hit.t == doctest::Approx(4.2).epsilon(1e-12));
    check_vec(hit.normal, 1, 0, 0);
    REQUIRE(hit_of(s, {-5, 0, 0}, {1, 0, 0}, hit, hit.t + 1e-9));
    CHECK(hit.t == doctest::Approx(5.8).epsilon(1e-12));  // into the far wall at x = 0.8
    check_vec(hit.normal, -1, 0, 0);
}

TEST_CASE("csg: a ray into a die's dimple hits the sphere's surface, normal out of the die") {
    const Scene s = parse(kDie);
    HitD hit;
    // Down the axis: the dimple's bottom at z = 1.2 - 0.5 = 0.7.
    REQUIRE(hit_of(s, {0, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == doctest::Approx(4.3).epsilon(1e-12));
    check_vec(hit.normal, 0, 0, 1);
    // At x = 0.3: the sphere at z = 1.2 - 0.4 = 0.8, where its own normal is (0.6, 0, -0.8);
    // the die's surface there faces the other way, up and toward the axis.
    REQUIRE(hit_of(s, {0.3, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == doctest::Approx(4.2).epsilon(1e-12));
    check_vec(hit.point, 0.3, 0, 0.8);
    check_vec(hit.normal, -0.6, 0, 0.8);
    CHECK(s.csg_shapes[std::size_t(hit.object) - s.objects.size()].kind == ShapeKind::Sphere);
    // Outside the dimple (x = 0.6 > 0.4, the dimple's radius at z = 1) the cube's face.
    REQUIRE(hit_of(s, {0.6, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
    check_vec(hit.normal, 0, 0, 1);
}

TEST_CASE("csg: shadow rays are blocked by the result, not by what was removed") {
    const Scene s = parse(kPipe);
    const RecursiveRenderer r(s);
    CHECK(!r.occluded(RayD{{0, 10, 0}, {0, -1, 0}}, 20.0));  // down the hole
    CHECK(r.occluded(RayD{{-5, 0, 0}, {1, 0, 0}}, 20.0));    // through the wall
    CHECK(!r.occluded(RayD{{-5, 0, 0}, {1, 0, 0}}, 3.9));    // stops short of the wall
    // From inside the hole, sideways within the removed cylinder: the wall is 0.8 away.
    CHECK(!r.occluded(RayD{{0, 0, 0}, {1, 0, 0}}, 0.7));
    CHECK(r.occluded(RayD{{0, 0, 0}, {1, 0, 0}}, 0.9));
}

namespace {

// A lit scene around a CSG object or plain shapes, small enough to compare every pixel.
std::string lit_scene(const std::string& objects) {
    return "image width=48 height=32 degree=5\n"
           "camera eye=0,1,6 look=0,0,0 fov=40\n"
           "light point pos=4,5,6 color=1,1,1\n"
           "plane translate=0,-1.5,0 color=0.5,0.5,0.5\n" +
           objects;
}

Framebuffer recursive_image(const std::string& text) {
    Parallelism par(1);
    return render_scene(parse(text), EngineKind::Recursive, par).image;
}

/// The number of pixels whose colour differs at all.
int differing_pixels(const Framebuffer& a, const Framebuffer& b) {
    REQUIRE(a.width == b.width);
    REQUIRE(a.height == b.height);
    int n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c)
                if (a.pixel(x, y)[c] != b.pixel(x, y)[c]) {
                    ++n;
                    break;
                }
    return n;
}

}  // namespace

TEST_CASE("csg: A union B and B union A give the same picture") {
    const std::string a = "  sphere translate=-0.5,0,0 color=1,0,0\n";
    const std::string b = "  cube scale=0.7,0.7,0.7 translate=0.4,0.2,0 color=0,0,1 refl=0.3\n";
    const Framebuffer ab = recursive_image(lit_scene("csg union\n" + a + b + "end\n"));
    const Framebuffer ba = recursive_image(lit_scene("csg union\n" + b + a + "end\n"));
    CHECK(differing_pixels(ab, ba) == 0);
    // Not a picture of nothing: the object covers pixels the floor alone does not.
    CHECK(differing_pixels(ab, recursive_image(lit_scene(""))) > 100);
}

TEST_CASE("csg: a difference with a disjoint child is its first child alone") {
    const std::string first = "sphere color=1,0.5,0 spec=0.5 shininess=20";
    const Framebuffer plain = recursive_image(lit_scene(first + "\n"));
    const Framebuffer csg =
        recursive_image(lit_scene("csg difference\n  " + first + "\n  cylinder translate=10,0,0\nend\n"));
    CHECK(differing_pixels(plain, csg) == 0);
    CHECK(differing_pixels(plain, recursive_image(lit_scene(""))) > 100);
}

namespace {

/// The walk (csg_first_boundary) over hand-made spans, one slot per shape: "t slot e|x in|out"
/// of the first boundary past t_min, or "none".
std::string walk(const Scene& scene, std::initializer_list<std::pair<double, double>> spans, double t_min = 0.0,
                 double t_max = kInf) {
    const CsgObject& o = scene.csg_objects[0];
    const CsgSlotLayout layout = csg_slot_layout(scene, o);
    REQUIRE(std::size_t(layout.slots()) == spans.size());
    CsgLine<double> line;
    std::array<std::uint8_t, kMaxCsgShapes> live;
    int n = 0;
    for (const auto& [e, x] : spans) {
        line.enter[std::size_t(n)] = e;
        line.exit[std::size_t(n)] = x;
        live[std::size_t(n)] = std::uint8_t(n);
        ++n;
    }
    const CsgFirst<double> at = csg_first_boundary(scene.csg_nodes.data(), o.root, layout, line, live.data(), n, t_min,
                                                   t_max, csg_shows_inner_surfaces(scene.csg_nodes.data(), o.root));
    if (!(at.t < t_max)) return "none";
    std::ostringstream s;
    s << at.t << " " << at.slot << (at.at_exit ? " x " : " e ") << (at.entering ? "in" : "out");
    return s.str();
}

}  // namespace

TEST_CASE("csg: the walk along a line over spans given by hand") {
    const Scene merge = parse("csg merge\n sphere\n sphere\nend\n");
    const Scene inter = parse("csg intersection\n sphere\n sphere\nend\n");
    const Scene diff = parse("csg difference\n sphere\n sphere\nend\n");
    // Overlapping spans [1, 4] and [2, 6].
    CHECK(walk(merge, {{1, 4}, {2, 6}}) == "1 0 e in");
    CHECK(walk(merge, {{1, 4}, {2, 6}}, 1.5) == "6 1 x out");  // no inner surface at 4 (or 2)
    CHECK(walk(inter, {{1, 4}, {2, 6}}) == "2 1 e in");
    CHECK(walk(inter, {{1, 4}, {2, 6}}, 2) == "4 0 x out");
    CHECK(walk(diff, {{1, 4}, {2, 6}}) == "1 0 e in");
    CHECK(walk(diff, {{1, 4}, {2, 6}}, 1) == "2 1 e out");  // the removed shape's enter closes it
    CHECK(walk(diff, {{2, 6}, {1, 4}}) == "4 1 x in");      // its exit opens it
    CHECK(walk(diff, {{2, 6}, {1, 4}}, 0, 3.5) == "none");
    // Spans that touch join: no surface where they meet.
    CHECK(walk(merge, {{0.5, 2}, {2, 3}}, 1) == "3 1 x out");
    CHECK(walk(inter, {{0.5, 2}, {2, 3}}) == "none");
    // Coinciding ends: the class after both; the first shape's surface shown.
    CHECK(walk(merge, {{1, 3}, {1, 5}}) == "1 0 e in");
    CHECK(walk(inter, {{1, 3}, {1, 5}}) == "1 0 e in");
    CHECK(walk(diff, {{1, 3}, {1, 2}}) == "2 1 x in");  // the base's face removed with the other's
    CHECK(walk(diff, {{1, 3}, {0, 3}}) == "none");
    // A span of length 0 (a tangent line) holds nothing; an empty one (a miss) neither.
    CHECK(walk(diff, {{1, 3}, {2, 2}}) == "1 0 e in");
    CHECK(walk(diff, {{1, 3}, {2, 2}}, 1) == "3 0 x out");
    CHECK(walk(merge, {{kInf, -kInf}, {2, 3}}) == "2 1 e in");
    // A line starting inside the result: the first way out.
    CHECK(walk(merge, {{-1, 3}, {2, 5}}) == "5 1 x out");
    // An infinite end (a half-space) is no surface.
    CHECK(walk(inter, {{-kInf, 3}, {1, kInf}}) == "1 1 e in");
    CHECK(walk(inter, {{-kInf, 3}, {1, kInf}}, 1) == "3 0 x out");
    CHECK(walk(merge, {{-kInf, 3}, {1, kInf}}) == "none");
}

TEST_CASE("csg: a union keeps its children's inner surfaces, unless it is subtracted") {
    const Scene uni = parse("csg union\n sphere\n sphere\nend\n");
    // Overlapping spans [1, 4] and [2, 6]: every end is a surface, each facing out of its shape.
    CHECK(walk(uni, {{1, 4}, {2, 6}}) == "1 0 e in");
    CHECK(walk(uni, {{1, 4}, {2, 6}}, 1.5) == "2 1 e in");
    CHECK(walk(uni, {{1, 4}, {2, 6}}, 2) == "4 0 x out");
    CHECK(walk(uni, {{1, 4}, {2, 6}}, 4) == "6 1 x out");
    // Touching spans: the first shape's exit where they meet; coinciding enters: the first's.
    CHECK(walk(uni, {{0.5, 2}, {2, 3}}, 1) == "2 0 x out");
    CHECK(walk(uni, {{1, 3}, {1, 5}}) == "1 0 e in");
    CHECK(walk(uni, {{1, 3}, {1, 5}}, 1) == "3 0 x out");
    // Inside a half-space, the other shape's enter is a surface; an infinite end still is not.
    CHECK(walk(uni, {{-kInf, 3}, {1, kInf}}) == "1 1 e in");
    CHECK(walk(uni, {{-kInf, 3}, {1, kInf}}, 1) == "3 0 x out");
    CHECK(walk(uni, {{-kInf, 3}, {1, kInf}}, 3) == "none");

    // Subtracted, a union is the intersection of what it leaves: no inner surface. The base
    // [1, 10] minus the union of [2, 5] and [4, 7]: out at 2, back in at 7 only.
    const Scene cut = parse("csg difference\n sphere\n csg union\n  sphere\n  sphere\n end\nend\n");
    CHECK(walk(cut, {{1, 10}, {2, 5}, {4, 7}}, 1) == "2 1 e out");
    CHECK(walk(cut, {{1, 10}, {2, 5}, {4, 7}}, 2) == "7 2 x in");
    // Twice subtracted, it keeps them: the base minus (a cutter minus the union).
    const Scene twice =
        parse("csg difference\n sphere\n csg difference\n  sphere\n  csg union\n   sphere\n   sphere\n  end\n end\nend\n");
    CHECK(walk(twice, {{1, 10}, {1.5, 9}, {2, 5}, {4, 7}}, 1.5) == "2 2 e in");
    CHECK(walk(twice, {{1, 10}, {1.5, 9}, {2, 5}, {4, 7}}, 2) == "4 3 e in");
    CHECK(walk(twice, {{1, 10}, {1.5, 9}, {2, 5}, {4, 7}}, 4) == "5 2 x out");

    // Inside an intersection, a union's inner surfaces where the other child holds the point
    // on both sides: [1, 4.5] with the union of [2, 5] and [4, 7].
    const Scene within = parse("csg intersection\n sphere\n csg union\n  sphere\n  sphere\n end\nend\n");
    CHECK(walk(within, {{1, 10}, {2, 5}, {4, 7}}, 2) == "4 2 e in");
    CHECK(walk(within, {{1, 10}, {2, 5}, {4, 7}}, 4) == "5 1 x out");
    CHECK(walk(within, {{1, 10}, {2, 5}, {4, 7}}, 5) == "7 2 x out");
    CHECK(walk(within, {{1, 4.5}, {2, 5}, {4, 7}}, 4) == "4.5 0 x out");  // 5 lies outside the first child
    CHECK(walk(within, {{1, 4}, {2, 5}, {4, 7}}, 2) == "4 0 x out");      // 4 ends the first child too
}

namespace {

void check_box(const CsgBox& b, glm::dvec3 lo, glm::dvec3 hi) {
    for (int a = 0; a < 3; ++a) {
        CHECK(b.lo[a] == doctest::Approx(lo[a]).epsilon(1e-12));
        CHECK(b.hi[a] == doctest::Approx(hi[a]).epsilon(1e-12));
    }
}

CsgBox box_of(const std::string& text) {
    const Scene s = parse(text);
    return csg_node_box(s, s.csg_objects[0].root);
}

}  // namespace

TEST_CASE("csg: a node is bounded by its result") {
    // Intersection: the overlap of the spheres' boxes, |z| <= 0.5.
    check_box(box_of(kLens), {-2, -2, -0.5}, {2, 2, 0.5});
    // Difference: the first child's box.
    check_box(box_of(kPipe), {-1, -2, -1}, {1, 2, 1});
    // Union: the box of both.
    check_box(box_of("csg union\n sphere translate=-3,0,0\n sphere translate=3,0,1\nend\n"), {-4, -1, -1}, {4, 1, 2});
    // Nested: the union's box cut by a cube of half-size 2 at the origin.
    check_box(box_of("csg intersection\n cube scale=2\n csg union\n  sphere translate=-3,0,0\n  sphere translate=3,0,1\n"
                     " end\nend\n"),
              {-2, -1, -1}, {2, 1, 2});
    // The plane's half-space has no box: cutting keeps the other's, joining loses it.
    const CsgBox cut = box_of("csg intersection\n plane\n cube\nend\n");
    check_box(cut, {-1, -1, -1}, {1, 1, 1});
    CHECK(!box_of("csg union\n plane\n cube\nend\n").bounded());
    // Children that cannot overlap leave an empty box.
    CHECK(box_of("csg intersection\n sphere translate=-3,0,0\n sphere translate=3,0,0\nend\n").empty());
}

TEST_CASE("csg: a ray is culled by its object's box only where it surely stays out") {
    const CsgBox lens = box_of(kLens);  // z in [-0.5, 0.5]: from z = 10 down, t in [9.5, 10.5]
    const Vec3d from{0, 0, 10}, down{0, 0, -1};
    CHECK(!ray_may_meet(lens, from, down, 0.0, 9.4));
    CHECK(ray_may_meet(lens, from, down, 0.0, 9.6));
    CHECK(ray_may_meet(lens, from, down, 10.4, kInf));
    CHECK(!ray_may_meet(lens, from, down, 10.6, kInf));
    CHECK(!ray_may_meet(lens, Vec3d{2.1, 0, 10}, down, 0.0, kInf));
    // A ray grazing the box's face is kept: the box is widened, never narrowed.
    CHECK(ray_may_meet(lens, Vec3d{2, 0, 10}, down, 0.0, kInf));
    const CsgBox nothing = box_of("csg intersection\n sphere translate=-3,0,0\n sphere translate=3,0,0\nend\n");
    CHECK(!ray_may_meet(nothing, from, down, 0.0, kInf));
    CHECK(ray_may_meet(box_of("csg union\n plane\n cube\nend\n"), Vec3d{50, 0, 10}, down, 0.0, kInf));
}

TEST_CASE("csg: the sphere's span from one solve has the bits of hit_t run both ways") {
    // solid_span takes the sphere's span from one solve (SphereMath::span); it must equal the
    // convex_span of every other convex solid, hit_t forwards and backwards, to the bit: in
    // float and double, on lines that hit, graze and miss, near and far from the centre.
    std::mt19937 rng(49);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const double scale = std::pow(10.0, 4 * u(rng));  // 1e-4 .. 1e4 radii away
        const Vec3d o{scale * u(rng), scale * u(rng), scale * u(rng)};
        const Vec3d to{1.2 * u(rng), 1.2 * u(rng), 1.2 * u(rng)};
        const Vec3d d = (to - o) * (0.5 + u(rng) * 0.4);
        const SpanT<double> one = solid_span<SphereMath>(o, d, 0.0), two = convex_span<SphereMath>(o, d, 0.0);
        CHECK(std::memcmp(&one, &two, sizeof one) == 0);
        const Vec3f of{float(o.x), float(o.y), float(o.z)}, df{float(d.x), float(d.y), float(d.z)};
        const SpanT<float> onef = solid_span<SphereMath>(of, df, 0.f), twof = convex_span<SphereMath>(of, df, 0.f);
        CHECK(std::memcmp(&onef, &twof, sizeof onef) == 0);
        hits += one.enter < one.exit;
    }
    CHECK(hits > 5000);  // most lines cross the sphere
    CHECK(hits < 19000);
}
