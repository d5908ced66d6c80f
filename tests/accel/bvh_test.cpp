// The object hierarchy against brute force: closest hit and any hit, scalar (baseline) and
// every SIMD traversal kernel the CPU runs, on random scenes of 1..1000 objects.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "parallel/parallelism.h"
#include "scene/scene_bvh.h"
#include "kernels/accel_kernel_table.h"
#include "shapes/shapes.h"
#include "stream/stream_accel.h"

using namespace streamrt;

namespace {

Scene random_scene(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Scene s;
    const double side = 3.0 * std::cbrt(double(n));
    for (std::size_t i = 0; i < n; ++i) {
        Object o;
        const int k = int(rng() % 5);  // sphere, cube, cylinder, cone, torus
        o.kind = ShapeKind(k);
        o.param = k == int(ShapeKind::Torus) ? 0.3 : 0.0;
        const glm::dmat4 md = translate_matrix({side * u(rng), side * u(rng), side * u(rng)}) *
                              rotate_y_matrix(180 * u(rng)) * rotate_x_matrix(180 * u(rng)) *
                              scale_matrix({0.3 + std::abs(u(rng)), 0.3 + std::abs(u(rng)), 0.3 + std::abs(u(rng))});
        o.md = glm::dmat4x3(md);
        s.add_object(o);
    }
    if (seed % 2) {  // a plane, which stays outside the hierarchy
        Object p;
        p.kind = ShapeKind::Plane;
        p.md = glm::dmat4x3(translate_matrix({0, -side, 0}));
        s.add_object(p);
    }
    return s;
}

double brute_t(const Scene& s, const Vec3d& o, const Vec3d& d, double t_max, int* id) {
    double best = t_max;
    *id = -1;
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
        const Object& ob = s.objects[i];
        const glm::dmat4 mi(affine_inverse(ob.md));
        const Vec3d oc = to_vec(transform_point(mi, to_glm(o)));
        const Vec3d dc = to_vec(transform_vector(mi, to_glm(d)));
        const double t =
            visit_shape(ob.kind, [&](auto shape) { return shape.template hit_t<double>(oc, dc, ob.param, 0.0, best); });
        if (t < best) {
            best = t;
            *id = int(i);
        }
    }
    return best;
}

double bvh_t(const Scene& s, const accel::SceneBvh& b, const Vec3d& o, const Vec3d& d, double t_max, int* id) {
    double best = t_max;
    *id = -1;
    const auto test = [&](std::uint32_t i, double& tm) {
        const Object& ob = s.objects[i];
        const glm::dmat4 mi(affine_inverse(ob.md));
        const Vec3d oc = to_vec(transform_point(mi, to_glm(o)));
        const Vec3d dc = to_vec(transform_vector(mi, to_glm(d)));
        const double t =
            visit_shape(ob.kind, [&](auto shape) { return shape.template hit_t<double>(oc, dc, ob.param, 0.0, tm); });
        if (t < tm) {
            tm = t;
            *id = int(i);
            return true;
        }
        return false;
    };
    for (std::uint32_t i : b.unbounded) test(i, best);
    accel::traverse_closest<double>(b.bvh, o, d, best, [&](std::uint32_t first, std::uint32_t count, double& tm) {
        for (std::uint32_t k = first; k < first + count; ++k) test(b.bvh.prim_index[k], tm);
    });
    return best;
}

struct Rays {
    std::vector<Vec3d> o, d;
};
Rays random_rays(std::size_t n, double side, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Rays r;
    for (std::size_t i = 0; i < n; ++i) {
        Vec3d o{1.5 * side * u(rng), 1.5 * side * u(rng), 1.5 * side * u(rng)};
        Vec3d d{u(rng), u(rng), u(rng)};
        if (i % 7 == 0) d = Vec3d{0, 0, 1};  // axis-aligned: infinite inverse components
        r.o.push_back(o);
        r.d.push_back(normalize(d));
    }
    return r;
}

}  // namespace

TEST_CASE("BVH: scalar closest and any hit equal brute force (1..1000 objects)") {
    for (std::size_t n : {1, 2, 3, 5, 8, 17, 64, 200, 1000}) {
        const Scene s = random_scene(n, std::uint32_t(n));
        const auto b = accel::SceneBvh::build(s);
        const double side = 3.0 * std::cbrt(double(n));
        const Rays r = random_rays(2000, side, 7 + std::uint32_t(n));
        for (std::size_t i = 0; i < r.o.size(); ++i) {
            int id_a, id_b;
            const double ta = brute_t(s, r.o[i], r.d[i], std::numeric_limits<double>::infinity(), &id_a);
            const double tb = bvh_t(s, *b, r.o[i], r.d[i], std::numeric_limits<double>::infinity(), &id_b);
            CHECK(ta == tb);
            CHECK(id_a == id_b);
            // any hit on a segment, a little shorter or longer than the closest hit
            for (double tm : {0.5 * side, std::isinf(ta) ? 10.0 : ta * 0.999, std::isinf(ta) ? 20.0 : ta * 1.001}) {
                int dummy;
                const bool brute = brute_t(s, r.o[i], r.d[i], tm, &dummy) < tm;
                Scene only_unbounded;
                for (std::uint32_t u : b->unbounded) only_unbounded.objects.push_back(s.objects[u]);
                bool any = brute_t(only_unbounded, r.o[i], r.d[i], tm, &dummy) < tm;
                if (!any)
                    any = accel::traverse_any<double>(b->bvh, r.o[i], r.d[i], tm,
                                                      [&](std::uint32_t first, std::uint32_t count, double t) {
                                                          Scene leaf;
                                                          for (std::uint32_t k = first; k < first + count; ++k)
                                                              leaf.objects.push_back(s.objects[b->bvh.prim_index[k]]);
                                                          return brute_t(leaf, r.o[i], r.d[i], t, &dummy) < t;
                                                      });
                CHECK(brute == any);
            }
        }
    }
}

TEST_CASE("BVH: SIMD packet and single-ray kernels agree with the flat kernels, every ISA") {
    for (std::size_t n : {1, 4, 9, 100, 1000}) {
        const Scene s = random_scene(n, 100 + std::uint32_t(n));
        const double side = 3.0 * std::cbrt(double(n));
        const Rays r = random_rays(1000, side, 3 + std::uint32_t(n));
        StreamAccel sa(s, accel::SceneBvh::build(s), accel::AccelConfig{});
        for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
            if (!isa_supported(isa)) continue;
            const KernelTable& kt = kernel_table(isa);
            // Flat reference: every object in its kind's kernel.
            std::vector<ObjectXf> groups[kShapeKindCount];
            for (std::size_t i = 0; i < s.objects.size(); ++i)
                groups[int(s.objects[i].kind)].push_back(kernel_object(s, i, std::int32_t(i), glm::dvec3(0.0)).xf);
            const auto make = [&](RayStream& rs, float t_max) {
                rs.reserve(r.o.size());
                for (std::size_t i = 0; i < r.o.size(); ++i) {
                    rs.ox[i] = float(r.o[i].x), rs.oy[i] = float(r.o[i].y), rs.oz[i] = float(r.o[i].z);
                    rs.dx[i] = float(r.d[i].x), rs.dy[i] = float(r.d[i].y), rs.dz[i] = float(r.d[i].z);
                    rs.t_max[i] = t_max;
                }
                rs.count = r.o.size();
                rs.pad_tail();
            };
            RayStream flat;
            make(flat, std::numeric_limits<float>::infinity());
            AlignedVec<std::int32_t> flat_id(flat.capacity(), -1);
            for (int k = 0; k < kShapeKindCount; ++k)
                if (!groups[k].empty()) kt.closest[k](view_of(flat), flat_id.data(), groups[k].data(), groups[k].size());
            for (accel::Traversal tr : {accel::Traversal::Packet, accel::Traversal::Single}) {
                accel::AccelConfig config;
                config.primary = config.shadow = tr;
                StreamAccel sa2(s, accel::SceneBvh::build(s), config);
                RayStream rs;
                make(rs, std::numeric_limits<float>::infinity());
                AlignedVec<std::int32_t> id(rs.capacity(), -1);
                sa2.closest(kt, view_of(rs), id.data(), true);
                for (std::size_t i = 0; i < rs.count; ++i) {
                    // The hierarchy's ids index its leaf-ordered records; map them back.
                    CHECK((id[i] < 0 ? -1 : std::int32_t(sa2.scene_index(id[i]))) == flat_id[i]);
                    CHECK(rs.t_max[i] == flat.t_max[i]);
                }
                // any hit on segments that end before the first hit (half-way, and 0.1 % short
                // of it: must not be blocked, whatever lies beyond t_max) and that reach past it
                // (0.1 % beyond: must be blocked). Rays that hit nothing get a 1e3 segment
                // (must not be blocked). The 0.1 % margin is ~1e4 float ulps of t: far above
                // the kernels' rounding of t (the closest-hit check above asks for equality).
                for (float f : {0.5f, 0.999f, 1.001f}) {
                    StreamAccel sa3(s, accel::SceneBvh::build(s), config);
                    RayStream sh;
                    make(sh, 0.f);
                    for (std::size_t i = 0; i < sh.count; ++i)
                        sh.t_max[i] = std::isinf(flat.t_max[i]) ? 1e3f : flat.t_max[i] * f;
                    sa3.any(kt, view_of(sh));
                    std::size_t short_hits = 0, long_hits = 0;
                    for (std::size_t i = 0; i < sh.count; ++i) {
                        const bool blocked = sh.t_max[i] == 0.f;
                        const bool expect = f > 1.f && flat_id[i] >= 0;
                        short_hits += f < 1.f && flat_id[i] >= 0;
                        long_hits += expect;
                        CHECK(blocked == expect);
                    }
                    // Both kinds of segment are really there.
                    if (f < 1.f) CHECK(short_hits > 0);
                    else CHECK(long_hits > 0);
                }
            }
        }
    }
}

namespace {
/// The levels of wide nodes on the longest path from the root, walked here (BuildStats::depth
/// says the same from the build).
int levels_walked(const accel::Bvh& b) {
    if (b.nodes.empty()) return 0;
    std::vector<std::pair<std::int32_t, int>> todo{{0, 1}};
    int deepest = 0;
    while (!todo.empty()) {
        const auto [node, level] = todo.back();
        todo.pop_back();
        deepest = std::max(deepest, level);
        const accel::WideNode& n = b.nodes[std::size_t(node)];
        for (int j = 0; j < accel::kNodeWidth; ++j)
            if (n.child[j] >= 0 && n.count[j] == 0) todo.push_back({n.child[j], level + 1});
    }
    return deepest;
}
}  // namespace

TEST_CASE("BVH: build of an empty set, a single box and many equal boxes") {
    CHECK(accel::Bvh::build({}).empty());
    CHECK(accel::Bvh::build({}).stats.depth == 0);
    accel::Aabb b;
    b.lo[0] = b.lo[1] = b.lo[2] = 0;
    b.hi[0] = b.hi[1] = b.hi[2] = 1;
    const accel::Bvh one = accel::Bvh::build({b});
    REQUIRE(one.nodes.size() == 1);
    CHECK(one.nodes[0].count[0] == 1);
    CHECK(one.stats.depth == 1);  // the root alone
    const accel::Bvh many = accel::Bvh::build(std::vector<accel::Aabb>(1000, b));
    std::size_t total = 0;
    for (const auto& n : many.nodes)
        for (int j = 0; j < accel::kNodeWidth; ++j) total += n.count[j];
    CHECK(total == 1000);
    CHECK(many.prim_index.size() == 1000);
    // 1000 boxes in leaves of at most 4 need at least 250 leaves, more than the 8 x 8 that two
    // levels of wide nodes can hold: at least 3 levels (equal boxes split at their median).
    CHECK(many.stats.depth >= 3);
    CHECK(many.stats.depth == levels_walked(many));
}

TEST_CASE("BVH: the tree's depth is the longest path of wide nodes (random boxes)") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 100.f);
    for (const int n : {9, 100, 5000}) {
        CAPTURE(n);
        auto boxes = std::vector<accel::Aabb>(std::size_t(n));
        for (auto& b : boxes)
            for (int a = 0; a < 3; ++a) b.lo[a] = u(rng), b.hi[a] = b.lo[a] + 1.f;
        const accel::Bvh bvh = accel::Bvh::build(boxes);
        CHECK(bvh.stats.depth == levels_walked(bvh));
        // At least n / 4 leaves (at most 4 boxes a leaf), and L levels hold at most 8^L.
        if (n == 5000) CHECK(bvh.stats.depth >= 4);  // 1250 leaves > 8^3
    }
}

TEST_CASE("BVH: the build from a box function leaves empty boxes out and makes the vector form's tree") {
    // 40 unit cubes along x at 0, 2, 4, ...; every fifth primitive has an empty box (a
    // default Aabb, lo > hi), as a degenerate primitive would.
    const auto box_of = [](std::size_t k) {
        accel::Aabb b;
        if (k % 5 == 3) return b;
        b.lo[0] = float(2 * k), b.hi[0] = float(2 * k + 1);
        b.lo[1] = b.lo[2] = 0.f, b.hi[1] = b.hi[2] = 1.f;
        return b;
    };
    std::vector<accel::Aabb> boxes;
    for (std::size_t k = 0; k < 40; ++k) boxes.push_back(box_of(k));
    for (const int jobs : {1, 2}) {
        CAPTURE(jobs);
        Parallelism par(jobs);
        const accel::Bvh f = par.run([&] { return accel::Bvh::build(40, box_of); });
        // The 32 non-empty primitives, none of 3, 8, 13, ...
        REQUIRE(f.prim_index.size() == 32);
        for (const std::uint32_t p : f.prim_index) CHECK(p % 5 != 3);
        CHECK(f.bounds.lo[0] == 0.f);
        CHECK(f.bounds.hi[0] == 79.f);  // cube 39 spans x = 78 .. 79
        const accel::Bvh v = accel::Bvh::build(boxes);
        CHECK(f.prim_index == v.prim_index);
        REQUIRE(f.nodes.size() == v.nodes.size());
        for (std::size_t i = 0; i < f.nodes.size(); ++i) {
            CAPTURE(i);
            CHECK(std::memcmp(&f.nodes[i], &v.nodes[i], sizeof(accel::WideNode)) == 0);
        }
    }
    CHECK(accel::Bvh::build(0, box_of).empty());
}

TEST_CASE("BVH: the collapse into 8-wide nodes takes the least-cost cut (16 boxes in a row, by hand)") {
    // Unit cubes at x = 0, 2, ..., 30, one per leaf (max_leaf 1): the binned SAH splits the row
    // in halves down to single boxes (a perfect binary tree of 16 leaves). A box spanning n
    // cubes has half-area 2 (2n - 1) + 1: 63 for the row, 31 for 8 cubes, 15 for 4, 7 for 2.
    // A wide node of k children costs area (1 + k / 4) (wide_child_cost 0.25). By hand:
    //   root over 8 nodes of 2 leaves:  63 * 3    + 8 * 7 * 1.5  = 273
    //   root over 2 nodes of 8 leaves:  63 * 1.5  + 2 * 31 * 3   = 280.5
    //   root over 4 nodes of 4 leaves:  63 * 2    + 4 * 15 * 2   = 246
    // and 246 is the least over every cut (an exhaustive search of them agrees; e.g. 3 quads
    // and 2 pairs cost 63 * 2.25 + 3 * 30 + 2 * 10.5 = 252.75). The greedy collapse (open
    // the largest child until 8) gave the first: 9 nodes.
    std::vector<accel::Aabb> row(16);
    for (int i = 0; i < 16; ++i) {
        row[std::size_t(i)].lo[0] = float(2 * i);
        row[std::size_t(i)].hi[0] = float(2 * i + 1);
        row[std::size_t(i)].lo[1] = row[std::size_t(i)].lo[2] = 0.f;
        row[std::size_t(i)].hi[1] = row[std::size_t(i)].hi[2] = 1.f;
    }
    accel::BuildOptions opt;
    opt.max_leaf = 1;
    opt.wide_child_cost = 0.25f;
    const accel::Bvh bvh = accel::Bvh::build(row, opt);
    REQUIRE(bvh.nodes.size() == 5);
    CHECK(bvh.stats.depth == 2);  // the root and its four quads
    const accel::WideNode& root = bvh.nodes[0];
    for (int j = 0; j < accel::kNodeWidth; ++j) {
        CAPTURE(j);
        if (j >= 4) {
            CHECK(root.child[j] == -1);
            continue;
        }
        REQUIRE(root.count[j] == 0);  // an inner node ...
        CHECK(root.hi_x[j] - root.lo_x[j] == 7.f);  // ... over 4 cubes
        const accel::WideNode& quad = bvh.nodes[std::size_t(root.child[j])];
        for (int k = 0; k < accel::kNodeWidth; ++k) CHECK(quad.count[k] == (k < 4 ? 1u : 0u));
    }
    // Without the cost of testing children the least total area of nodes is 63 + 31 + 7 = 101:
    // the root over one node of 8 leaves, one of 2 and 6 leaves (8 pairs: 63 + 56 = 119).
    opt.wide_child_cost = 0.f;
    const accel::Bvh flat = accel::Bvh::build(row, opt);
    REQUIRE(flat.nodes.size() == 3);
    int leaves = 0, inner = 0;
    for (int j = 0; j < accel::kNodeWidth; ++j) {
        leaves += flat.nodes[0].count[j] == 1;
        inner += flat.nodes[0].child[j] >= 0 && flat.nodes[0].count[j] == 0;
    }
    CHECK(leaves == 6);
    CHECK(inner == 2);
    CHECK(flat.stats.depth == 2);
}
