// The disk (x^2 + z^2 <= 1 in the plane y = 0, normal +y), added through the shape registry
// (shapes/shapes.h): analytic hits in the shape math, in every kernel at every ISA, through
// the object hierarchy (which must not cull a hit), and rendered by both engines.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "driver/render.h"
#include "kernels/kernel_table.h"
#include "render/one_pixel.h"
#include "scene/parser.h"
#include "scene/scene_bvh.h"
#include "shapes/shapes.h"
#include "stream/stream_accel.h"
#include "stream/stream_scene.h"

using namespace streamrt;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();

struct Case {
    const char* what;
    Vec3d o, d;
    double t;  ///< expected hit, kInf for a miss
};

// Every expected t is exact in float too (the operands are small binary fractions), except
// the nearly parallel ray, compared with a relative tolerance.
const Case kCases[] = {
    {"straight down onto the centre", {0, 2, 0}, {0, -1, 0}, 2},
    {"down at a known point", {0.3, 2, -0.4}, {0, -1, 0}, 2},
    {"oblique, lands at (0.5, 0, 0)", {0, 1, 0}, {0.5, -1, 0}, 1},
    {"non-unit direction: t scales", {0, 2, 0}, {0, -4, 0}, 0.5},
    {"from below onto the underside", {0, -3, 0.5}, {0, 1, 0}, 3},
    {"just inside the rim", {0.9990234375, 1, 0}, {0, -1, 0}, 1},
    {"just outside the rim", {1.0009765625, 1, 0}, {0, -1, 0}, kInf},
    {"outside the rim on the diagonal", {0.75, 1, 0.75}, {0, -1, 0}, kInf},
    {"away from the disk", {0, 2, 0}, {0, 1, 0}, kInf},
    {"parallel, above", {-5, 0.001, 0}, {1, 0, 0}, kInf},
    {"parallel, lying in its plane", {-5, 0, 0}, {1, 0, 0}, kInf},
    {"grazing: nearly parallel, crosses y = 0 at x = 0", {-5, 0.0009765625, 0}, {1, -0.0001953125, 0}, 5},
    {"grazing: nearly parallel, crosses y = 0 at x = 3", {-5, 0.0009765625, 0}, {1, -0.0001220703125, 0}, kInf},
    {"starting on the disk (t = 0 is not > 0)", {0.2, 0, 0.2}, {0, 1, 0}, kInf},
};

void check_t(double got, double want, const char* what) {
    CAPTURE(what);
    if (std::isinf(want)) CHECK(got == kInf);
    else CHECK(got == doctest::Approx(want).epsilon(1e-6));
}

/// Mi of an identity object with the given id.
ObjectXf identity_object(std::int32_t id) {
    ObjectXf o{};
    o.m[0] = o.m[5] = o.m[10] = 1.f;
    o.id = id;
    return o;
}

void fill(RayStream& rs, const std::vector<Vec3d>& o, const std::vector<Vec3d>& d, float t_max) {
    rs.reserve(o.size());
    for (std::size_t i = 0; i < o.size(); ++i) {
        rs.ox[i] = float(o[i].x), rs.oy[i] = float(o[i].y), rs.oz[i] = float(o[i].z);
        rs.dx[i] = float(d[i].x), rs.dy[i] = float(d[i].y), rs.dz[i] = float(d[i].z);
        rs.t_max[i] = t_max;
    }
    rs.count = o.size();
    rs.pad_tail();
}

std::vector<Isa> supported_isas() {
    std::vector<Isa> v;
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512})
        if (isa_supported(isa)) v.push_back(isa);
    return v;
}

}  // namespace

TEST_CASE("disk: registered, named, flat bounds, normal +y") {
    CHECK(std::string(shape_kind_name(ShapeKind::Disk)) == "disk");
    CHECK(canonical_shape_named("disk") == ShapeKind::Disk);
    const CanonicalBounds b = canonical_bounds(ShapeKind::Disk, 0.0);
    CHECK(b.form == CanonicalBounds::Form::Box);
    CHECK((b.lo[0] == -1 && b.lo[1] == 0 && b.lo[2] == -1 && b.hi[0] == 1 && b.hi[1] == 0 && b.hi[2] == 1));
    const Vec3d n = DiskMath::normal<double>({0.3, 0, 0.4}, 0.0);
    CHECK((n.x == 0 && n.y == 1 && n.z == 0));
}

TEST_CASE("disk: analytic hits, misses and grazing rays (double and float)") {
    for (const Case& c : kCases) {
        check_t(DiskMath::hit_t<double>(c.o, c.d, 0.0, 0.0, kInf), c.t, c.what);
        const double tf = DiskMath::hit_t<float>(vec_cast<float>(c.o), vec_cast<float>(c.d), 0.f, 0.f, kInfF);
        check_t(tf, c.t, c.what);
    }
    // t_max and t_min bound the hit.
    CHECK(DiskMath::hit_t<double>({0, 2, 0}, {0, -1, 0}, 0.0, 0.0, 1.5) == kInf);
    CHECK(DiskMath::hit_t<double>({0, 2, 0}, {0, -1, 0}, 0.0, 2.5, kInf) == kInf);
    // Poisoned rays miss instead of giving NaN.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK(DiskMath::hit_t<double>({0, 2, 0}, {nan, -1, 0}, 0.0, 0.0, kInf) == kInf);
    CHECK(DiskMath::hit_t<double>({nan, 2, 0}, {0, -1, 0}, 0.0, 0.0, kInf) == kInf);
    CHECK(DiskMath::hit_t<double>({0, 2, 0}, {0, 0, 0}, 0.0, 0.0, kInf) == kInf);
}

TEST_CASE("disk kernels: the analytic cases at every ISA (closest, any, culled)") {
    std::vector<Vec3d> o, d;
    for (const Case& c : kCases) o.push_back(c.o), d.push_back(c.d);
    const std::vector<ObjectXf> objs = {identity_object(3)};
    // The box the flat kernels cull with: the disk's own, barely padded.
    const ObjectBounds box{{-1.0001f, -1e-6f, -1.0001f}, {1.0001f, 1e-6f, 1.0001f}};
    const int disk = int(ShapeKind::Disk);
    for (Isa isa : supported_isas()) {
        CAPTURE(isa_name(isa));
        const KernelTable& kt = kernel_table(isa);
        for (bool culled : {false, true}) {
            CAPTURE(culled);
            RayStream rs;
            fill(rs, o, d, kInfF);
            AlignedVec<std::int32_t> id(rs.capacity(), -1);
            if (culled) kt.closest_culled[disk](view_of(rs), id.data(), objs.data(), &box, 1);
            else kt.closest[disk](view_of(rs), id.data(), objs.data(), 1);
            for (std::size_t i = 0; i < rs.count; ++i) {
                const bool hit = !std::isinf(kCases[i].t);
                check_t(hit ? double(rs.t_max[i]) : (id[i] < 0 ? kInf : 0.0), kCases[i].t, kCases[i].what);
                CHECK(id[i] == (hit ? 3 : -1));
            }
            // Any hit: blocked when the hit lies before t_max, open when just beyond it.
            for (float scale : {1.01f, 0.99f}) {
                RayStream sh;
                fill(sh, o, d, 0.f);
                for (std::size_t i = 0; i < sh.count; ++i)
                    sh.t_max[i] = std::isinf(kCases[i].t) ? 100.f : float(kCases[i].t) * scale;
                if (culled) kt.any_culled[disk](view_of(sh), objs.data(), &box, 1);
                else kt.any[disk](view_of(sh), objs.data(), 1);
                for (std::size_t i = 0; i < sh.count; ++i) {
                    CAPTURE(kCases[i].what);
                    CHECK((sh.t_max[i] == 0.f) == (!std::isinf(kCases[i].t) && scale > 1.f));
                }
            }
        }
    }
}

namespace {

/// n disks: half only scaled and translated (a box of zero thickness before padding), half
/// rotated as well; on a field of side ~ 3 cbrt(n).
Scene random_disks(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Scene s;
    // The eye at the origin: the stream engine's records are relative to it.
    s.settings.width = s.settings.height = 16;
    s.camera.look_at = true;
    s.camera.eye = {0, 0, 0};
    s.camera.look = {0, 0, -1};
    const double side = 3.0 * std::cbrt(double(n));
    for (std::size_t i = 0; i < n; ++i) {
        Object o;
        o.kind = ShapeKind::Disk;
        glm::dmat4 md = scale_matrix({0.3 + std::abs(u(rng)), 0.3 + std::abs(u(rng)), 0.3 + std::abs(u(rng))});
        if (i % 2) md = rotate_y_matrix(180 * u(rng)) * rotate_x_matrix(180 * u(rng)) * md;
        md = translate_matrix({side * u(rng), side * u(rng), side * u(rng)}) * md;
        o.md = glm::dmat4x3(md);
        s.add_object(o);
    }
    return s;
}

/// Rays aimed at points of the disks, many near the rim (radius 0.98 .. 1 in canonical
/// units), some grazing (origin just off the disk's plane), plus random rays.
void disk_rays(const Scene& s, std::size_t n, std::uint32_t seed, std::vector<Vec3d>& o, std::vector<Vec3d>& d) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double side = 3.0 * std::cbrt(double(s.objects.size()));
    for (std::size_t i = 0; i < n; ++i) {
        const Object& ob = s.objects[rng() % s.objects.size()];
        const double a = 3.14159265358979 * u(rng);
        const double r = i % 3 == 0 ? std::sqrt(std::abs(u(rng))) : 0.98 + 0.02 * std::abs(u(rng));
        const glm::dvec3 target = ob.md * glm::dvec4(r * std::cos(a), 0, r * std::sin(a), 1);
        glm::dvec3 from{2 * side * u(rng), 2 * side * u(rng), 2 * side * u(rng)};
        if (i % 5 == 0)  // grazing: from a point barely above the disk's plane, far away along it
            from = glm::dvec3(ob.md * glm::dvec4(8 * u(rng), 1e-3 * u(rng), 8 * u(rng), 1));
        if (i % 7 == 0) from = target + glm::dvec3(0, 0, 3);  // along -z: infinite inverse components
        const glm::dvec3 dir = glm::normalize(i % 11 == 0 ? glm::dvec3(u(rng), u(rng), u(rng)) : target - from);
        o.push_back({from.x, from.y, from.z});
        d.push_back({dir.x, dir.y, dir.z});
    }
}

double brute_t(const Scene& s, const Vec3d& o, const Vec3d& d, int* id) {
    double best = kInf;
    *id = -1;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
        const glm::dmat4 mi(affine_inverse(s.objects[i].md));
        const Vec3d oc = to_vec(transform_point(mi, to_glm(o))), dc = to_vec(transform_vector(mi, to_glm(d)));
        const double t = DiskMath::hit_t<double>(oc, dc, 0.0, 0.0, best);
        if (t < best) best = t, *id = int(i);
    }
    return best;
}

}  // namespace

TEST_CASE("disk: the hierarchy never culls a disk hit (scalar and SIMD traversal, flat culling boxes)") {
    for (std::size_t n : {3, 6, 40, 500}) {  // under and above the hierarchy's threshold (8)
        CAPTURE(n);
        const Scene s = random_disks(n, 11 + std::uint32_t(n));
        std::vector<Vec3d> o, d;
        disk_rays(s, 3000, 5 + std::uint32_t(n), o, d);
        // Scalar traversal (the recursive engine's) against brute force, exactly.
        const auto b = accel::SceneBvh::build(s);
        CHECK(b->unbounded.empty());
        std::size_t hits = 0;
        for (std::size_t i = 0; i < o.size(); ++i) {
            int id_a, id_b = -1;
            const double ta = brute_t(s, o[i], d[i], &id_a);
            double tb = kInf;
            const auto leaf = [&](std::uint32_t first, std::uint32_t count, double& tm) {
                for (std::uint32_t k = first; k < first + count; ++k) {
                    const std::uint32_t j = b->bvh.prim_index[k];
                    const glm::dmat4 mi(affine_inverse(s.objects[j].md));
                    const double t = DiskMath::hit_t<double>(to_vec(transform_point(mi, to_glm(o[i]))),
                                                             to_vec(transform_vector(mi, to_glm(d[i]))), 0.0, 0.0, tm);
                    if (t < tm) tm = t, id_b = int(j);
                }
            };
            accel::traverse_closest<double>(b->bvh, o[i], d[i], tb, leaf);
            hits += id_a >= 0;
            CHECK(ta == tb);
            CHECK(id_a == id_b);
        }
        CHECK(hits > o.size() / 2);
        // SIMD: flat kernels with no boxes = the truth at float precision; the flat kernels
        // with the stream engine's culling boxes and the hierarchy kernels must agree with it.
        accel::AccelConfig flat;
        flat.mode = accel::AccelMode::Flat;
        const StreamScene flat_scene(s, flat);
        const auto& group = flat_scene.groups[int(ShapeKind::Disk)];
        const auto& boxes = flat_scene.group_bounds[int(ShapeKind::Disk)];
        REQUIRE(group.size() == n);
        for (Isa isa : supported_isas()) {
            CAPTURE(isa_name(isa));
            const KernelTable& kt = kernel_table(isa);
            RayStream truth, culled;
            fill(truth, o, d, kInfF);
            fill(culled, o, d, kInfF);
            AlignedVec<std::int32_t> id_t(truth.capacity(), -1), id_c(truth.capacity(), -1);
            kt.closest[int(ShapeKind::Disk)](view_of(truth), id_t.data(), group.data(), n);
            kt.closest_culled[int(ShapeKind::Disk)](view_of(culled), id_c.data(), group.data(), boxes.data(), n);
            std::size_t culled_wrong = 0, bvh_wrong = 0;
            for (std::size_t i = 0; i < truth.count; ++i)
                culled_wrong += id_c[i] != id_t[i] || culled.t_max[i] != truth.t_max[i];
            CHECK(culled_wrong == 0);
            for (accel::Traversal tr : {accel::Traversal::Packet, accel::Traversal::Single}) {
                accel::AccelConfig config;
                config.primary = config.shadow = tr;
                StreamAccel sa(s, accel::SceneBvh::build(s), config);
                RayStream rs;
                fill(rs, o, d, kInfF);
                AlignedVec<std::int32_t> id(rs.capacity(), -1);
                sa.closest(kt, view_of(rs), id.data(), true);
                for (std::size_t i = 0; i < rs.count; ++i) {
                    const std::int32_t got = id[i] < 0 ? -1 : std::int32_t(sa.scene_index(id[i]));
                    bvh_wrong += got != id_t[i] || rs.t_max[i] != truth.t_max[i];
                }
                // Any hit just beyond the closest hit: every ray that hits is blocked.
                RayStream sh;
                fill(sh, o, d, 0.f);
                for (std::size_t i = 0; i < sh.count; ++i)
                    sh.t_max[i] = std::isinf(truth.t_max[i]) ? 1e4f : truth.t_max[i] * 1.001f;
                sa.any(kt, view_of(sh));
                for (std::size_t i = 0; i < sh.count; ++i) bvh_wrong += (sh.t_max[i] == 0.f) != (id_t[i] >= 0);
            }
            CHECK(bvh_wrong == 0);
        }
    }
}

namespace {

const std::string kPixelHead =
    "image width=1 height=1 spp=1 depth=0 degree=1\n"
    "ambient 0.1\n"
    "background 0.2,0.3,0.4\n";

void check_pixel(const std::string& body, double r, double g, double b) {
    test::check_one_pixel(parse_scene(kPixelHead + body, "disk_pixel.cfg"), r, g, b);
}

}  // namespace

TEST_CASE("disk: both engines render it, from above and from below (one-sided, normal faces the viewer)") {
    const std::string disk = "disk color=0.8,0.4,0.2\n";
    // Looking down onto the disk, light above: Lambert 1 plus ambient 0.1.
    check_pixel("camera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=10\nlight point pos=0,10,0\n" + disk, 0.88, 0.44, 0.22);
    // From below, light below: the normal is turned to face the viewer, so lit the same.
    check_pixel("camera eye=0,-5,0 look=0,0,0 up=0,0,-1 fov=10\nlight point pos=0,-10,0\n" + disk, 0.88, 0.44, 0.22);
    // From below, light above: the light is behind the surface seen: ambient only.
    check_pixel("camera eye=0,-5,0 look=0,0,0 up=0,0,-1 fov=10\nlight point pos=0,10,0\n" + disk, 0.08, 0.04, 0.02);
    // Past the rim: the background (a plane there would be hit).
    check_pixel("camera eye=1.2,5,0 look=1.2,0,0 up=0,0,-1 fov=10\nlight point pos=0,10,0\n" + disk, 0.2, 0.3, 0.4);
}

TEST_CASE("disk: engines agree on many-disk scenes, flat and through the hierarchy, every ISA and shade path") {
    for (int n : {6, 120}) {  // under and above the hierarchy's threshold
        CAPTURE(n);
        std::string text =
            "image width=48 height=32 spp=1 depth=2 degree=5\n"
            "camera eye=0,6,9 look=0,0,0 fov=50\n"
            "ambient 0.1\nbackground 0.2,0.3,0.4\n"
            "light point pos=3,8,4\n";
        std::mt19937 rng{std::uint32_t(n)};
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        for (int i = 0; i < n; ++i)
            text += "disk color=0.8,0.5,0.3 diff=0.8 spec=0.3 refl=" + std::string(i % 3 ? "0" : "0.4") +
                    " scale=" + std::to_string(0.4 + 0.3 * std::abs(u(rng))) +
                    " rotate_x=" + std::to_string(60 * u(rng)) + " rotate_z=" + std::to_string(60 * u(rng)) +
                    " translate=" + std::to_string(4 * u(rng)) + "," + std::to_string(2 * u(rng)) + "," +
                    std::to_string(4 * u(rng)) + "\n";
        const Scene scene = parse_scene(text, "disks.cfg");
        Parallelism par(1);
        const Framebuffer ref = render_scene(scene, EngineKind::Recursive, par).image;
        const auto compare = [&](const Framebuffer& img) {
            std::size_t bad = 0;
            double lit = 0;
            for (std::size_t k = 0; k < img.rgb.size(); ++k) {
                bad += std::abs(img.rgb[k] - ref.rgb[k]) > 2e-3f;
                lit += ref.rgb[k];
            }
            CHECK(bad <= img.rgb.size() / 200);  // float vs double at silhouettes
            CHECK(lit > 0.3 * double(img.rgb.size()) * 0.2);
        };
        for (accel::AccelMode mode : {accel::AccelMode::Flat, accel::AccelMode::Auto}) {
            EngineOptions recursive;
            recursive.accel.mode = mode;
            compare(render_scene(scene, EngineKind::Recursive, par, nullptr, recursive).image);
            for (Isa isa : supported_isas())
                for (ShadeMode sm : {ShadeMode::Sorted, ShadeMode::Gathered, ShadeMode::Scalar}) {
                    CAPTURE(isa_name(isa));
                    CAPTURE(int(sm));
                    EngineOptions opt;
                    opt.isa = isa;
                    opt.shade = sm;
                    opt.accel.mode = mode;
                    compare(render_scene(scene, EngineKind::Stream, par, nullptr, opt).image);
                }
        }
    }
}
