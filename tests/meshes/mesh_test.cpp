// Triangle meshes: the watertight triangle test in double, float and every SIMD level (flat
// kernels and the scene hierarchy's packet and single-ray walks) never lets a ray through a
// closed mesh or between triangles at shared edges and vertices; tessellated spheres against
// the analytic sphere; OBJ files through the parser; both engines on a mesh scene.
#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene_bvh.h"
#include "image/image_compare.h"
#include "kernels/kernel_table.h"
#include "mesh/mesh.h"
#include "mesh/mesh_trace.h"
#include "parallel/parallelism.h"
#include "render/camera_rays.h"
#include "driver/render.h"
#include "scene/parser.h"
#include "stream/stream_accel.h"
#include "stream/stream_scene.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

struct Rays {
    std::vector<Vec3f> o, d;
    void add(const Vec3f& a, const Vec3f& b) {
        o.push_back(a);
        d.push_back(b);
    }
};

/// Adds mesh m to scene s as an object placed by md.
void add_mesh_object(Scene& s, const std::shared_ptr<const Mesh>& m, const glm::dmat4& md = glm::dmat4(1.0)) {
    Object o;
    o.kind = ShapeKind::Mesh;
    o.mesh = std::uint32_t(s.meshes.size());
    o.md = glm::dmat4x3(md);
    s.meshes.push_back(m);
    s.add_object(o);
}

void fill(RayStream& rs, const Rays& r, float t_max) {
    rs.reserve(r.o.size());
    for (std::size_t i = 0; i < r.o.size(); ++i) {
        rs.ox[i] = r.o[i].x, rs.oy[i] = r.o[i].y, rs.oz[i] = r.o[i].z;
        rs.dx[i] = r.d[i].x, rs.dy[i] = r.d[i].y, rs.dz[i] = r.d[i].z;
        rs.t_max[i] = t_max;
    }
    rs.count = r.o.size();
    rs.pad_tail();
}

/// Every ray must hit the mesh (placed with the identity) for some t in (0, t_limit): checked
/// with the baseline's double walk, the same walk in float, and on every ISA level the flat
/// mesh kernels (closest and any hit) and the scene hierarchy's packet and single-ray walks.
void check_all_hit(const std::shared_ptr<const Mesh>& mesh, const Rays& r, float t_limit = kInfF) {
    const MeshView& mv = mesh->view();
    std::size_t miss_d = 0, miss_f = 0;
    for (std::size_t i = 0; i < r.o.size(); ++i) {
        double td = t_limit;
        std::uint32_t tri = 0;
        double u = 0, v = 0;
        if (!mesh_closest<double>(mv, mesh->bvh, vec_cast<double>(r.o[i]), vec_cast<double>(r.d[i]), 0.0, td, tri, u, v))
            ++miss_d;
        float tf = t_limit, uf = 0, vf = 0;
        if (!mesh_closest<float>(mv, mesh->bvh, r.o[i], r.d[i], 0.f, tf, tri, uf, vf)) ++miss_f;
    }
    CHECK(miss_d == 0);
    CHECK(miss_f == 0);

    Scene s;
    add_mesh_object(s, mesh);
    // The stream engine's flat scene, for its per-object culling boxes: the eye at the origin,
    // so that its frame (relative to the eye) is the mesh's.
    s.camera.look_at = true;
    s.camera.eye = {0.0, 0.0, 0.0};
    s.camera.look = {0.0, 0.0, -1.0};
    accel::AccelConfig flat;
    flat.mode = accel::AccelMode::Flat;
    const StreamScene flat_scene(s, flat);
    REQUIRE(flat_scene.groups[int(ShapeKind::Mesh)].size() == 1);
    REQUIRE(flat_scene.group_bounded[int(ShapeKind::Mesh)]);
    ObjectXf xf{};
    xf.m[0] = xf.m[5] = xf.m[10] = 1.f;
    xf.id = 0;
    xf.mesh = &mv;
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const std::string isa_str = isa_name(isa);
        CAPTURE(isa_str);
        const KernelTable& kt = kernel_table(isa);
        // Packet walk only, the hybrid, single-ray walk only (MeshView::single_ray_lanes).
        for (std::uint32_t lanes : {0u, 2u, 64u}) {
            CAPTURE(lanes);
            const auto walk = mesh->with_single_ray_lanes(lanes);
            xf.mesh = &walk->view();
            RayStream rs;
            fill(rs, r, t_limit);
            AlignedVec<std::int32_t> id(rs.capacity(), -1), prim(rs.capacity(), -1);
            AlignedVec<float> bu(rs.capacity()), bv(rs.capacity());
            RayView view = view_of(rs);
            view.prim = prim.data(), view.bu = bu.data(), view.bv = bv.data();
            kt.closest[int(ShapeKind::Mesh)](view, id.data(), &xf, 1);
            std::size_t misses = 0, bad_prim = 0;
            for (std::size_t i = 0; i < rs.count; ++i) {
                misses += id[i] != 0;
                bad_prim += prim[i] < 0 || std::uint32_t(prim[i]) >= mv.n_tris;
            }
            CHECK(misses == 0);
            CHECK(bad_prim == 0);
            RayStream sh;
            fill(sh, r, t_limit == kInfF ? 1e30f : t_limit);
            kt.any[int(ShapeKind::Mesh)](view_of(sh), &xf, 1);
            std::size_t open = 0;
            for (std::size_t i = 0; i < sh.count; ++i) open += sh.t_max[i] != 0.f;
            CHECK(open == 0);
        }
        // The flat kernels that first test each mesh's world box (padded: a ray that meets the
        // mesh always meets its box, at the box's corners and edges included).
        {
            const ObjectXf* group = flat_scene.groups[int(ShapeKind::Mesh)].data();
            const ObjectBounds* box = flat_scene.group_bounds[int(ShapeKind::Mesh)].data();
            RayStream rs;
            fill(rs, r, t_limit);
            AlignedVec<std::int32_t> id(rs.capacity(), -1);
            kt.closest_culled[int(ShapeKind::Mesh)](view_of(rs), id.data(), group, box, 1);
            std::size_t misses = 0;
            for (std::size_t i = 0; i < rs.count; ++i) misses += id[i] != 0;
            CHECK(misses == 0);
            RayStream sh;
            fill(sh, r, t_limit == kInfF ? 1e30f : t_limit);
            kt.any_culled[int(ShapeKind::Mesh)](view_of(sh), group, box, 1);
            std::size_t open = 0;
            for (std::size_t i = 0; i < sh.count; ++i) open += sh.t_max[i] != 0.f;
            CHECK(open == 0);
        }
        xf.mesh = &mv;
        for (accel::Traversal tr : {accel::Traversal::Packet, accel::Traversal::Single}) {
            accel::AccelConfig config;
            config.primary = config.shadow = tr;
            StreamAccel sa(s, accel::SceneBvh::build(s), config);
            RayStream rs2;
            fill(rs2, r, t_limit);
            AlignedVec<std::int32_t> id2(rs2.capacity(), -1);
            sa.closest(kt, view_of(rs2), id2.data(), true);
            std::size_t m2 = 0;
            for (std::size_t i = 0; i < rs2.count; ++i) m2 += id2[i] != 0;
            CHECK(m2 == 0);
            RayStream sh2;
            fill(sh2, r, t_limit == kInfF ? 1e30f : t_limit);
            sa.any(kt, view_of(sh2));
            std::size_t o2 = 0;
            for (std::size_t i = 0; i < sh2.count; ++i) o2 += sh2.t_max[i] != 0.f;
            CHECK(o2 == 0);
        }
    }
}

Vec3f random_unit(std::mt19937& rng) {
    std::normal_distribution<float> n(0.f, 1.f);
    for (;;) {
        const Vec3f v{n(rng), n(rng), n(rng)};
        const float l = length(v);
        if (l > 1e-3f) return v * (1.f / l);
    }
}

std::shared_ptr<const Mesh> build(const MeshData& d) { return Mesh::build("generated", d.positions, d.triangles); }

}  // namespace

TEST_CASE("meshes: triangle test basics, both faces, barycentrics, t range") {
    const Vec3d p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
    const WatertightRay<double> r = watertight_ray(Vec3d{0.25, 0.5, 1}, Vec3d{0, 0, -2});
    const TriangleHit<double> h = triangle_hit(r, p0, p1, p2, 0.0, 10.0);
    CHECK(h.t == doctest::Approx(0.5));
    CHECK(h.u == doctest::Approx(0.25));
    CHECK(h.v == doctest::Approx(0.5));
    // from below (back face) too
    const WatertightRay<double> back = watertight_ray(Vec3d{0.25, 0.5, -1}, Vec3d{0, 0, 1});
    CHECK(triangle_hit(back, p0, p1, p2, 0.0, 10.0).t == doctest::Approx(1.0));
    // outside, beyond t_max, behind the origin
    CHECK(std::isinf(triangle_hit(watertight_ray(Vec3d{0.8, 0.8, 1}, Vec3d{0, 0, -1}), p0, p1, p2, 0.0, 10.0).t));
    CHECK(std::isinf(triangle_hit(r, p0, p1, p2, 0.0, 0.4).t));
    CHECK(std::isinf(triangle_hit(watertight_ray(Vec3d{0.25, 0.5, 1}, Vec3d{0, 0, 1}), p0, p1, p2, 0.0, 10.0).t));
    // parallel to the plane of the triangle
    CHECK(std::isinf(triangle_hit(watertight_ray(Vec3d{-1, 0.2, 0}, Vec3d{1, 0, 0}), p0, p1, p2, 0.0, 10.0).t));
    // float agrees
    const WatertightRay<float> rf = watertight_ray(Vec3f{0.25f, 0.5f, 1}, Vec3f{0, 0, -2});
    CHECK(triangle_hit(rf, Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0}, 0.f, 10.f).t == doctest::Approx(0.5f));
}

TEST_CASE("meshes: the any-hit triangle test without division: both faces, t range, misses") {
    // t = 0.5 along (0, 0, -2) from z = 1 (front face), t = 1 along (0, 0, 1) from z = -1 (back).
    const Vec3f p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
    const WatertightRay<float> front = watertight_ray(Vec3f{0.25f, 0.5f, 1}, Vec3f{0, 0, -2});
    const WatertightRay<float> back = watertight_ray(Vec3f{0.25f, 0.5f, -1}, Vec3f{0, 0, 1});
    CHECK(triangle_blocks(front, p0, p1, p2, 0.51f));
    CHECK_FALSE(triangle_blocks(front, p0, p1, p2, 0.49f));
    CHECK_FALSE(triangle_blocks(front, p0, p1, p2, 0.5f));  // the interval is open at t_max
    CHECK(triangle_blocks(back, p0, p1, p2, 1.01f));
    CHECK_FALSE(triangle_blocks(back, p0, p1, p2, 0.99f));
    // behind the origin (T and det of opposite signs), outside the edges, parallel, idle lane
    CHECK_FALSE(triangle_blocks(watertight_ray(Vec3f{0.25f, 0.5f, 1}, Vec3f{0, 0, 1}), p0, p1, p2, 10.f));
    CHECK_FALSE(triangle_blocks(watertight_ray(Vec3f{0.8f, 0.8f, 1}, Vec3f{0, 0, -1}), p0, p1, p2, 10.f));
    CHECK_FALSE(triangle_blocks(watertight_ray(Vec3f{-1, 0.2f, 0}, Vec3f{1, 0, 0}), p0, p1, p2, 10.f));
    CHECK_FALSE(triangle_blocks(front, p0, p1, p2, 0.f));
    CHECK(triangle_blocks(front, p0, p1, p2, std::numeric_limits<float>::infinity()));
    // Away from t_max it agrees with the closest-hit test, ray for ray.
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-2.f, 2.f), tm(0.1f, 5.f);
    int blocked = 0;
    for (int i = 0; i < 20000; ++i) {
        const WatertightRay<float> r = watertight_ray(Vec3f{u(rng), u(rng), u(rng)}, Vec3f{u(rng), u(rng), u(rng)});
        const float t_max = tm(rng);
        const float t = triangle_hit(r, p0, p1, p2, 0.f, 1e30f).t;
        if (std::abs(t - t_max) < 1e-4f * t_max) continue;
        CHECK(triangle_blocks(r, p0, p1, p2, t_max) == (t < t_max));
        blocked += t < t_max;
    }
    CHECK(blocked > 100);  // the comparison saw both answers (193 of the 20000)
}

TEST_CASE("meshes: the closest-hit walks' division-free pre-test passes every lane the exact test hits") {
    // The walks skip a triangle's division when triangle_may_hit passes no lane; it must pass
    // every lane triangle_hit_sheared accepts, also with t_max one ulp beyond the hit, where the
    // two forms' roundings differ most.
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> u(-2.f, 2.f);
    const Vec3f p0{0.1f, -0.3f, 0.2f}, p1{1.3f, 0.1f, -0.4f}, p2{-0.2f, 1.1f, 0.5f};
    int at_limit = 0;
    for (int i = 0; i < 200000; ++i) {
        const Vec3f o{u(rng), u(rng), u(rng)};
        const Vec3f aim = p0 + (p1 - p0) * (0.5f * (u(rng) + 2.f) / 4.f) + (p2 - p0) * (0.5f * (u(rng) + 2.f) / 4.f);
        const WatertightRay<float> r = watertight_ray(o, (aim - o) * (0.25f + (u(rng) + 2.f)));
        const auto s = triangle_sheared(r, p0, p1, p2);
        const float t = triangle_hit_sheared(s, 0.f, std::numeric_limits<float>::infinity()).t;
        if (std::isinf(t)) continue;
        for (const float t_max : {std::nextafter(t, 1e30f), std::nextafter(std::nextafter(t, 1e30f), 1e30f), 2.f * t}) {
            const bool hit = triangle_hit_sheared(s, 0.f, t_max).t < t_max;
            at_limit += hit && t_max < 2.f * t;
            if (hit && !triangle_may_hit(s, t_max)) FAIL_CHECK("pre-test drops a hit at t ", t, ", t_max ", t_max);
        }
    }
    CHECK(at_limit > 100000);  // the exact test hit at one or two ulps beyond t on most rays
}

TEST_CASE("meshes: degenerate triangles are dropped, normals, memory") {
    const std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0};
    const auto m = Mesh::build("t", pos, {0, 1, 2, 0, 1, 3, 0, 0, 1, 0, 1, 7});
    CHECK(m->triangle_count() == 1);
    CHECK(m->dropped == 3);  // collinear, repeated vertex, missing vertex
    const Vec3d n = mesh_normal<double>(m->view(), 0, 0.3, 0.3, false);
    CHECK(n.z > 0);
    const Vec3d ns = mesh_normal<double>(m->view(), 0, 0.3, 0.3, true);
    CHECK(ns.z == doctest::Approx(1.0));
    CHECK(m->memory_bytes() > 0);
}

TEST_CASE("meshes: a closed cube mesh: 1e5 random rays from inside all hit (double, float, every SIMD level)") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.999f, 0.999f);
    for (int n : {1, 3}) {
        CAPTURE(n);
        const auto cube = build(cube_mesh(n));
        CHECK(cube->triangle_count() == std::size_t(12 * n * n));
        Rays r;
        for (int i = 0; i < 100000; ++i) r.add({u(rng), u(rng), u(rng)}, random_unit(rng));
        // From the centre exactly at the cube's vertices, edge points and grid lines.
        for (int i = 0; i < 2000; ++i) {
            const int a = int(rng() % 3);
            Vec3f t{float(int(rng() % 2) * 2 - 1), float(int(rng() % 2) * 2 - 1), float(int(rng() % 2) * 2 - 1)};
            const float g = -1.f + 2.f * float(rng() % std::uint32_t(n + 1)) / float(n);
            (a == 0 ? t.x : a == 1 ? t.y : t.z) = (i % 2) ? g : u(rng);
            r.add({0, 0, 0}, t);
            r.add({u(rng) * 0.5f, u(rng) * 0.5f, u(rng) * 0.5f}, t - r.o.back());
        }
        check_all_hit(cube, r);
        // From outside, entering the cube (its own bounding box) at t = 1 exactly at its
        // corners and on its edges, from every side and down to grazing angles: the hits that
        // a box test without padding loses to rounding. Each ray comes from the side of every
        // face it reaches, so it crosses into the cube there.
        Rays out;
        for (int i = 0; i < 20000; ++i) {
            Vec3f t{float(int(rng() % 2) * 2 - 1), float(int(rng() % 2) * 2 - 1), float(int(rng() % 2) * 2 - 1)};
            const int free_axis = i % 2 ? int(rng() % 3) : -1;  // an edge point: one coordinate free
            Vec3f away{};  // outward at t: along each face's normal there, a little or a lot
            for (int a = 0; a < 3; ++a) {
                float& c = a == 0 ? t.x : a == 1 ? t.y : t.z;
                float& w = a == 0 ? away.x : a == 1 ? away.y : away.z;
                if (a == free_axis) {
                    c = u(rng);
                    w = u(rng);
                } else {
                    w = c * (i % 7 == 0 ? 1e-3f : 0.05f + std::fabs(u(rng)));
                }
            }
            const Vec3f o = t + away * (2.f + 2.f * u(rng));
            out.add(o, t - o);
        }
        check_all_hit(cube, out, 1.0001f);
    }
}

TEST_CASE("meshes: the per-object box of the flat kernels never changes a hit, at a flat mesh's border included") {
    // A flat square (axis-aligned, its box has no thickness) and a cube, placed by a scale and
    // a move, with and without a rotation: rays from both sides aimed exactly at border points
    // (corners, edge points) and at random points, many at grazing angles. The box test before
    // each mesh's walk must give the same hits, distances and triangles as the walk alone, on
    // every level.
    const MeshData square{{-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, {0, 1, 2, 0, 2, 3}};
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const glm::dmat4 moved = glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, -1.7, 2.1)) *
                             glm::scale(glm::dmat4(1.0), glm::dvec3(1.5, 0.7, 2.0));
    const glm::dmat4 turned = moved * glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(1, 2, 3)));
    for (const auto& [d, md] : {std::pair{square, moved}, std::pair{square, turned}, std::pair{cube_mesh(1), moved},
                                std::pair{cube_mesh(1), turned}}) {
        const auto mesh = build(d);
        Scene s;
        add_mesh_object(s, mesh, md);
        s.camera.look_at = true;  // the engine's origin (the eye) at the world's
        s.camera.eye = {0.0, 0.0, 0.0};
        s.camera.look = {0.0, 0.0, -1.0};
        accel::AccelConfig flat;
        flat.mode = accel::AccelMode::Flat;
        const StreamScene sc(s, flat);
        const ObjectXf* group = sc.groups[int(ShapeKind::Mesh)].data();
        const ObjectBounds* box = sc.group_bounds[int(ShapeKind::Mesh)].data();
        REQUIRE(sc.group_bounded[int(ShapeKind::Mesh)]);
        // In packets of 16 rays that share which of their target's coordinates sit on the
        // border, and on which side (the box is tested per packet: a packet is left out only
        // when all its rays miss the box).
        const bool flat_mesh = d.positions.size() == 12;
        Rays r;
        for (int packet = 0; packet < 2000; ++packet) {
            const int on_border = packet % (flat_mesh ? 3 : 4);  // 0 - 2 coordinates (3 on the cube)
            const glm::dvec3 side(rng() % 2 ? 1.0 : -1.0, rng() % 2 ? 1.0 : -1.0, rng() % 2 ? 1.0 : -1.0);
            const bool grazing = packet % 5 == 0;  // nearly along the square's plane
            for (int k = 0; k < 16; ++k) {
                glm::dvec3 p(u(rng), u(rng), flat_mesh ? 0.0 : u(rng));
                for (int a = 0; a < on_border; ++a) p[a] = side[a];
                const glm::dvec3 target = glm::dvec3(md * glm::dvec4(p, 1.0));
                glm::dvec3 from(u(rng), u(rng), u(rng));
                if (grazing) from.z *= 1e-3;
                const glm::dvec3 o =
                    glm::dvec3(md * glm::dvec4(p + glm::normalize(from) * (0.5 + 2.0 * std::fabs(u(rng))), 1.0));
                r.add(Vec3f{float(o.x), float(o.y), float(o.z)},
                      Vec3f{float(target.x - o.x), float(target.y - o.y), float(target.z - o.z)});
            }
        }
        for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
            if (!isa_supported(isa)) continue;
            const std::string isa_str = isa_name(isa);
            CAPTURE(isa_str);
            const KernelTable& kt = kernel_table(isa);
            RayStream walk, culled;
            fill(walk, r, 1.01f);
            fill(culled, r, 1.01f);
            AlignedVec<std::int32_t> id_w(walk.capacity(), -1), id_c(walk.capacity(), -1);
            AlignedVec<std::int32_t> prim_w(walk.capacity(), -1), prim_c(walk.capacity(), -1);
            AlignedVec<float> bu(walk.capacity()), bv(walk.capacity());
            RayView vw = view_of(walk), vc = view_of(culled);
            vw.prim = prim_w.data(), vc.prim = prim_c.data();
            vw.bu = vc.bu = bu.data(), vw.bv = vc.bv = bv.data();
            kt.closest[int(ShapeKind::Mesh)](vw, id_w.data(), group, 1);
            kt.closest_culled[int(ShapeKind::Mesh)](vc, id_c.data(), group, box, 1);
            std::size_t hits = 0, differ = 0;
            for (std::size_t i = 0; i < walk.count; ++i) {
                hits += id_w[i] == 0;
                differ += id_w[i] != id_c[i] || walk.t_max[i] != culled.t_max[i] || prim_w[i] != prim_c[i];
            }
            CHECK(hits > walk.count / 2);
            CHECK(differ == 0);
            RayStream sw, sc2;
            fill(sw, r, 1.01f);
            fill(sc2, r, 1.01f);
            kt.any[int(ShapeKind::Mesh)](view_of(sw), group, 1);
            kt.any_culled[int(ShapeKind::Mesh)](view_of(sc2), group, box, 1);
            std::size_t blocked_differ = 0;
            for (std::size_t i = 0; i < sw.count; ++i) blocked_differ += (sw.t_max[i] == 0.f) != (sc2.t_max[i] == 0.f);
            CHECK(blocked_differ == 0);
        }
    }
}

TEST_CASE("meshes: rays aimed exactly at shared edges and vertices of a tessellated sphere never miss") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    for (const MeshData& d : {uv_sphere(6, 12), uv_sphere(24, 48), icosphere(3)}) {
        const auto m = build(d);
        Rays from_out, from_in;
        for (std::size_t k = 0; k < d.triangles.size(); k += 3)
            for (int j = 0; j < 3; ++j) {
                const auto vtx = [&](std::size_t idx) {
                    const std::uint32_t v = d.triangles[idx];
                    return Vec3f{d.positions[3 * v], d.positions[3 * v + 1], d.positions[3 * v + 2]};
                };
                const Vec3f a = vtx(k + std::size_t(j)), b = vtx(k + std::size_t((j + 1) % 3));
                for (const Vec3f target : {a, (a + b) * 0.5f, a + (b - a) * u01(rng)}) {
                    const Vec3f o = normalize(target + random_unit(rng) * 0.7f) * 4.f;
                    from_out.add(o, target - o);  // reaches the surface at t ~ 1
                    from_in.add({0, 0, 0}, target);
                    const Vec3f inner = random_unit(rng) * (0.3f * u01(rng));
                    from_in.add(inner, target - inner);
                }
            }
        CAPTURE(m->triangle_count());
        check_all_hit(m, from_out, 1.001f);
        check_all_hit(m, from_in, 1.001f);
    }
}

TEST_CASE("meshes: tessellated spheres against the analytic sphere, silhouettes agree within the tessellation error") {
    constexpr int kSize = 64;
    const auto scene_with = [](const Object& o, const std::shared_ptr<const Mesh>& mesh) {
        Scene s;
        s.settings.width = s.settings.height = kSize;
        s.settings.spp = 1;
        s.settings.degree = 0;
        s.camera.look_at = true;
        s.camera.eye = {0.3, 0.5, 3.5};
        s.camera.fov = 40;
        if (mesh) add_mesh_object(s, mesh);
        else s.add_object(o);
        return s;
    };
    Object sphere;
    sphere.kind = ShapeKind::Sphere;
    const Scene analytic = scene_with(sphere, nullptr);
    const CameraRays<double> cam = CameraRays<double>::from(analytic);
    Parallelism par(2);
    std::size_t previous = std::size_t(-1);
    for (const MeshData& d : {uv_sphere(8, 16), uv_sphere(16, 32), uv_sphere(32, 64), uv_sphere(64, 128)}) {
        const auto m = build(d);
        // The inscribed polyhedron contains the ball of radius r_in (its nearest face plane).
        double r_in = 1.0;
        for (std::uint32_t k = 0; k < m->view().n_tris; ++k) {
            const Vec3d p0 = mesh_vertex<double>(m->view(), k, 0);
            const Vec3d n = normalize(mesh_normal<double>(m->view(), k, 0, 0, false));
            r_in = std::min(r_in, std::abs(dot(n, p0)));
        }
        CAPTURE(m->triangle_count());
        CAPTURE(r_in);
        const Scene tess = scene_with(Object{}, m);
        std::size_t outside_band = 0, extra = 0, differ = 0;
        for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
            const Framebuffer a = render_scene(analytic, e, par).image;
            const Framebuffer b = render_scene(tess, e, par).image;
            for (int y = 0; y < kSize; ++y)
                for (int x = 0; x < kSize; ++x) {
                    const bool in_a = a.pixel(x, y)[0] > 0.5f, in_b = b.pixel(x, y)[0] > 0.5f;
                    if (in_a == in_b) continue;
                    ++differ;
                    // distance of the pixel's ray from the centre
                    const Vec3d dir = cam.direction(x + 0.5, y + 0.5);
                    const Vec3d c = cam.origin - dir * dot(cam.origin, dir);
                    const double r_perp = length(c);
                    if (in_b && !in_a) ++extra;  // the mesh lies inside the sphere
                    else if (r_perp < r_in - 1e-4 || r_perp > 1 + 1e-4) ++outside_band;
                }
        }
        MESSAGE(m->triangle_count() << " triangles: r_in " << r_in << ", silhouette pixels differing " << differ);
        CHECK(extra <= 1);
        CHECK(outside_band == 0);
        CHECK(differ <= previous);
        previous = differ;
    }
    CHECK(previous <= 8);
}

TEST_CASE("meshes: an OBJ file through the parser, both engines agree, errors carry file:line:col") {
    const fs::path dir = fs::temp_directory_path() / ("streamrt_mesh_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    REQUIRE(write_obj((dir / "ball.obj").string(), icosphere(2)));
    REQUIRE(write_obj((dir / "box.obj").string(), cube_mesh(2)));
    {
        std::ofstream(dir / "empty.obj") << "# nothing\nv 0 0 0\n";
        std::ofstream(dir / "flat.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
        std::ofstream(dir / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    }
    const std::string cfg = (dir / "scene.cfg").string();
    const std::string text =
        "image width=96 height=72 spp=2 degree=5 depth=3\n"
        "camera eye=0,2,6 look=0,0.5,0\n"
        "light point pos=3,6,4\n"
        "plane color=0.5,0.5,0.5 checker=0.2,0.2,0.2\n"
        "mesh file=ball.obj smooth=true color=1,0.5,0.2 spec=0.5 translate=-1.2,1,0\n"
        "mesh file=ball.obj color=0.2,0.5,1 scale=0.7 translate=1.2,0.7,0\n"
        "mesh file=box.obj color=0.8,0.8,0.8 refl=0.5 scale=0.4 rotate_y=30 translate=0,0.4,-1.5\n"
        "mesh file=quad.obj scale=0.3 translate=0,0,1\n";
    const Scene s = parse_scene(text, cfg);
    REQUIRE(s.objects.size() == 5);
    CHECK(s.objects[1].kind == ShapeKind::Mesh);
    CHECK(s.objects[1].param == 1.0);  // smooth
    CHECK(s.objects[2].param == 0.0);
    CHECK(s.objects[1].mesh == s.objects[2].mesh);  // one file, loaded once
    CHECK(s.meshes.size() == 3);
    CHECK(s.mesh_of(s.objects[1])->triangle_count() == 320);
    CHECK(s.mesh_of(s.objects[4])->triangle_count() == 2);  // the quad, triangulated
    Parallelism par(2);
    for (accel::AccelMode mode : {accel::AccelMode::Flat, accel::AccelMode::Bvh}) {
        EngineOptions with_mode;
        with_mode.accel.mode = mode;
        const Framebuffer a = render_scene(s, EngineKind::Stream, par, nullptr, with_mode).image;
        const Framebuffer b = render_scene(s, EngineKind::Recursive, par, nullptr, with_mode).image;
        const ImageDifference d = compare_images(a, b);
        CAPTURE(d.psnr);
        CAPTURE(d.share_over);
        CHECK(d.psnr >= 50.0);
        CHECK(d.share_over <= 0.001);
        // The scalar shade stage gives the same picture as the SIMD one.
        EngineOptions opt = with_mode;
        opt.shade = ShadeMode::Scalar;
        const ImageDifference ds = compare_images(render_scene(s, EngineKind::Stream, par, nullptr, opt).image, a);
        CHECK(ds.psnr >= 50.0);
    }

    const auto error_of = [&](const std::string& t) {
        try {
            parse_scene(t, cfg);
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string where = cfg + ":2:";
    CHECK(error_of("\nmesh file=missing.obj\n").rfind(where + "11: cannot open mesh file", 0) == 0);
    CHECK(error_of("\nmesh file=empty.obj\n").find(where + "11:") == 0);
    CHECK(error_of("\nmesh file=empty.obj\n").find("no faces") != std::string::npos);
    CHECK(error_of("\nmesh file=flat.obj\n").find("non-zero area") != std::string::npos);
    CHECK(error_of("\nmesh file=. \n").rfind(where + "11:", 0) == 0);
    CHECK(error_of("\nmesh color=1,1,1\n").rfind(where + "1: mesh needs 'file=PATH'", 0) == 0);
    CHECK(error_of("\nmesh file=ball.obj smooth=yes\n").rfind(where + "27: expected true or false", 0) == 0);
    CHECK(error_of("\nsphere file=ball.obj\n").rfind(where + "8: unknown key 'file'", 0) == 0);
    fs::remove_all(dir);
}

TEST_CASE("meshes: the hybrid walk of deep rays (--mesh-hybrid) gives the packet walk's picture, byte for byte") {
    // Glass and mirror meshes at depth 6: from the fourth bounce on, packets of rays that
    // have scattered walk the meshes as packets until at most N of them reach a node, then one
    // by one (N = 64: one by one from the root). Both walks run the same watertight test, so
    // every hit, and every pixel, is the same; a lane dropped or mixed up in the hand-over
    // changes the picture. A lumpy, flat-shaded glass ball scatters the rays as a scanned
    // mesh does; a smooth one keeps them together (the packet walk).
    const fs::path dir = fs::temp_directory_path() / ("streamrt_hybrid_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    MeshData lumpy = icosphere(3);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> radius(0.8f, 1.2f);
    for (std::size_t v = 0; v < lumpy.positions.size(); v += 3) {
        const float r = radius(rng);
        for (int k = 0; k < 3; ++k) lumpy.positions[v + k] *= r;
    }
    REQUIRE(write_obj((dir / "lumpy.obj").string(), lumpy));
    REQUIRE(write_obj((dir / "ball.obj").string(), icosphere(3)));
    REQUIRE(write_obj((dir / "box.obj").string(), cube_mesh(3)));
    const std::string text =
        "image width=80 height=60 spp=2 degree=5 depth=6\n"
        "camera eye=0,1.5,5 look=0,0.6,0\n"
        "light point pos=3,6,4\n"
        "plane color=0.5,0.5,0.5 checker=0.2,0.2,0.2\n"
        "mesh file=lumpy.obj color=1,1,1 diff=0.1 trans=0.8 ior=1.5 translate=-0.6,0.8,0\n"
        "mesh file=ball.obj smooth=true color=1,1,1 diff=0.1 trans=0.8 ior=1.5 scale=0.4 translate=-0.2,0.4,1.5\n"
        "mesh file=box.obj color=0.9,0.9,0.9 diff=0.1 trans=0.8 ior=1.33 scale=0.5 rotate_y=30 translate=0.8,0.5,0.5\n"
        "mesh file=ball.obj color=0.9,0.9,0.9 refl=0.9 scale=0.6 translate=0.4,0.6,-1.5\n";
    const Scene s = parse_scene(text, (dir / "scene.cfg").string());
    Parallelism par(2);
    for (accel::AccelMode mode : {accel::AccelMode::Flat, accel::AccelMode::Bvh}) {
        EngineOptions packet;
        packet.accel.mode = mode;
        packet.accel.mesh_hybrid_lanes = 0;
        const RenderResult base = render_scene(s, EngineKind::Stream, par, nullptr, packet);
        REQUIRE(base.counts.refracted > 4000);  // rays through the glass: generations 1 to 6
        for (std::uint32_t lanes : {1u, 8u, 16u, 64u}) {
            CAPTURE(lanes);
            EngineOptions hybrid = packet;
            hybrid.accel.mesh_hybrid_lanes = lanes;
            const RenderResult h = render_scene(s, EngineKind::Stream, par, nullptr, hybrid);
            CHECK(h.counts.total() == base.counts.total());
            CHECK(h.image.rgb == base.image.rgb);
        }
    }
    fs::remove_all(dir);
}
