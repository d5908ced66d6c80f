// The SIMD CSG kernels (kernels/csg_kernel.h) against the scalar walk, lane by lane: every
// ray's t and record id (closest; on a mesh its triangle) and blocked flag (any) at every ISA
// level this machine runs, on random rays through CSG objects of every solid, nested, cut by a
// plane, with a closed mesh.
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "every_isa.h"
#include "kernels/kernel_table.h"
#include "render/csg_spans.h"
#include "scene/parser.h"
#include "stream/stream_scene.h"
#include "../render/csg_cases.h"

using namespace streamrt;

namespace {

struct Expected {
    float t;
    std::int32_t id;
    std::int32_t tri = -1;  ///< on a mesh: its triangle
};

/// The first CSG surface in (0, t_max) along o + t d, in scalar code (render/csg_spans.h's
/// walk with V = float, a mesh's spans by mesh_slot_spans) and without any box: what every
/// lane of the kernels must give, to the bit. The line is brought into each shape's space as
/// the kernels and the shade stage do (the same float Mi).
Expected scalar_closest(const CsgView& v, const Vec3f& o, const Vec3f& d, float t_max) {
    Expected e{t_max, -1};
    for (std::size_t k = 0; k < v.count; ++k) {
        const CsgObjectView& ob = v.objects[k];
        const auto canonical = [&](std::uint32_t shape) {
            const ObjectXf& xf = v.records[shape].xf;
            return std::pair{apply_point(xf.m, o), apply_vector(xf.m, d)};
        };
        CsgLine<float> line;
        std::array<CsgSlotEnds, kMaxCsgShapes> ends;
        std::array<std::uint8_t, kMaxCsgShapes> live;
        const int n = csg_scalar_line(
            ob.layout, canonical,
            [&](std::uint32_t shape) {
                const ObjectXf& xf = v.records[shape].xf;
                return std::tuple{ShapeKind(xf.kind), xf.param, v.meshes[shape]};
            },
            line, ends.data(), live.data());
        const CsgFirst<float> at = csg_first_boundary(v.nodes, ob.root, ob.layout, line, live.data(), n, 0.f, e.t,
                                                      csg_shows_inner_surfaces(v.nodes, ob.root));
        if (!(at.t < e.t)) continue;
        e.t = at.t;
        const auto slot = std::size_t(at.slot);
        const std::uint32_t shape = ob.layout.first_shape + ob.layout.shape_of[slot];
        const bool turned = v.meshes[shape] && ends[slot].turned[at.at_exit ? 1 : 0];
        e.id = v.first_id + std::int32_t(shape) + (csg_flip(at.at_exit, at.entering, turned) ? v.shapes : 0);
        e.tri = v.meshes[shape] ? std::int32_t(ends[slot].tri[at.at_exit ? 1 : 0]) : -1;
    }
    return e;
}

const char* const kScenes[] = {
    csg_cases::kLens, csg_cases::kPipe, csg_cases::kDie,
    // Every solid, nested four deep, a plane cutting it, and a second object.
    "csg difference\n"
    " csg intersection\n"
    "  cube scale=1.2\n"
    "  csg union\n"
    "   sphere scale=1.4\n"
    "   csg merge\n"
    "    cone scale=0.8,2,0.8\n"
    "    cylinder scale=0.5,1.6,0.5 rotate_z=90\n"
    "   end\n"
    "  end\n"
    " end\n"
    " plane rotate_x=180 translate=0,0.9,0\n"
    " sphere scale=0.6 translate=0.8,0.8,0.8\n"
    "end\n"
    "csg intersection translate=0,0,-3\n sphere\n plane rotate_z=30\nend\n",
    // Two-shape roots of every operation (combined in lanes), and coinciding spans: the tie rule.
    "csg union\n sphere translate=-0.5,0,0\n cube scale=0.7 translate=0.4,0.2,0\nend\n"
    "csg merge translate=0,0,-2\n cylinder scale=0.5,1,0.5\n cone rotate_x=90\nend\n",
    "csg union\n sphere\n sphere\nend\ncsg merge translate=1,1,-2\n cube\n cube\nend\n",
    "csg intersection\n sphere\n sphere\nend\ncsg difference translate=1,1,-2\n cube\n cube\nend\n"
    "csg difference translate=-1,-1,1\n sphere\n sphere\nend\n",
    "csg difference\n cube\n cube translate=0,0,1\nend\ncsg intersection translate=0,0,-2\n cube\n cube translate=1,0,0\nend\n"
    "csg union translate=0,2,0\n cube\n cube translate=2,0,0\nend\n",
    // A union's inner surfaces (a root of three, walked in lanes), and a subtracted union's none.
    "csg union\n sphere translate=-0.5,0,0\n sphere translate=0.5,0,0\n csg difference\n"
    "  cube scale=0.6 translate=0,0.8,0\n  csg union\n   sphere scale=0.4 translate=0,1,0\n"
    "   cylinder scale=0.2,2,0.2\n  end\n end\nend\n",
    // Tori: a ring cut, a slab minus a fat ring, a union with one (two slots each, in double lanes).
    "csg difference\n torus minor=0.5\n sphere scale=0.3 translate=1,0,0\nend\n"
    "csg difference translate=0,0,-2\n cube scale=1.2,0.4,1.2\n torus minor=1 rotate_x=20\nend\n"
    "csg union translate=1,1,1\n torus minor=0.3 rotate_z=80\n torus minor=0.3\n sphere scale=0.5\nend\n",
    // A closed mesh (1,280 triangles) minus a sphere, and in a tree of three: walked by packets.
    "csg difference\n mesh file=" STREAMRT_SOURCE_DIR "/scenes/csg/lumpy.obj\n"
    " sphere scale=0.75 translate=0.55,0.75,0.55\nend\n"
    "csg union translate=0.5,-0.5,-2.5\n sphere scale=0.5 translate=-1,0,0\n"
    " csg intersection\n  mesh file=" STREAMRT_SOURCE_DIR "/scenes/csg/lumpy.obj scale=0.9\n  cube scale=0.7\n end\n"
    " cylinder scale=0.3,1.5,0.3\nend\n",
};

/// kScenes and a field of CSG objects past AccelConfig::min_objects, walked through their
/// hierarchy (render/csg_hierarchy.h): 3 x 3 dice and tori cut flat, and a wall with a dent
/// (a half-space minus a sphere: an unbounded box, tested beside the tree).
std::vector<std::string> scenes() {
    std::vector<std::string> all(std::begin(kScenes), std::end(kScenes));
    std::string field;
    for (int i = 0; i < 9; ++i) {
        const std::string at = " translate=" + std::to_string(i % 3 - 1) + "," + std::to_string(i / 3 - 1) + ",0\n";
        field += i % 2 ? "csg difference scale=0.35" + at + " cube\n sphere scale=0.5 translate=0,0,1.2\nend\n"
                       : "csg intersection scale=0.35" + at + " torus minor=0.5\n cube scale=2,0.3,2\nend\n";
    }
    field += "csg difference rotate_x=90 translate=0,0,-3\n plane\n sphere scale=1.5\nend\n";
    all.push_back(field);
    return all;
}

}  // namespace

TEST_CASE("csg kernels: every lane's closest and any hit equal the scalar walk, every ISA") {
    for (const std::string& text : scenes()) {
        const Scene s = parse_scene(std::string("camera eye=0,0,8 look=0,0,0\nsphere translate=9,0,0\n") + text, "t.cfg");
        const StreamScene sc(s);
        REQUIRE(sc.csg);
        CHECK(sc.csg->view().tree == (s.csg_objects.size() >= 8));
        const CsgView& v = sc.csg->view();
        for (std::size_t n : {std::size_t(1), std::size_t(7), std::size_t(9), std::size_t(37), std::size_t(1000)}) {
            const unsigned seed = 4049u + unsigned(n);
            CAPTURE(n);
            CAPTURE(seed);
            std::mt19937 rng(seed);
            std::uniform_real_distribution<float> u(-1.f, 1.f);
            // Rays from around the objects (relative to the eye at z = 8) toward points near
            // them; a third with a finite t_max, so that intervals cut spans.
            RayStream rays;
            rays.reserve(n);
            rays.count = n;
            for (std::size_t i = 0; i < n; ++i) {
                const Vec3f from{4 * u(rng), 4 * u(rng), 4 * u(rng) - 8}, to{1.5f * u(rng), 1.5f * u(rng), 2 * u(rng) - 9};
                const Vec3f d = normalize(to - from);
                rays.ox[i] = from.x, rays.oy[i] = from.y, rays.oz[i] = from.z;
                rays.dx[i] = d.x, rays.dy[i] = d.y, rays.dz[i] = d.z;
                rays.t_max[i] = i % 3 == 0 ? 2 + 6 * (u(rng) + 1) : std::numeric_limits<float>::infinity();
            }
            rays.pad_tail();
            std::vector<Expected> want(n);
            std::size_t hits = 0;
            for (std::size_t i = 0; i < n; ++i) {
                want[i] = scalar_closest(v, {rays.ox[i], rays.oy[i], rays.oz[i]}, {rays.dx[i], rays.dy[i], rays.dz[i]},
                                         rays.t_max[i]);
                hits += want[i].id >= 0;
            }
            if (n >= 37) CHECK(hits * 5 >= n);  // the rays meet the objects
            at_every_isa([&](Isa isa) {
                const KernelTable& kt = kernel_table(isa);
                RayStream closest = rays;
                AlignedVec<std::int32_t> id(closest.capacity(), -1), prim(closest.capacity(), -1);
                AlignedVec<float> bu(closest.capacity()), bv(closest.capacity());
                RayView cv = view_of(closest);
                cv.prim = prim.data(), cv.bu = bu.data(), cv.bv = bv.data();
                kt.csg_closest(v, cv, id.data());
                RayStream any = rays;
                kt.csg_any(v, view_of(any));
                for (std::size_t i = 0; i < n; ++i) {
                    CAPTURE(i);
                    CHECK(id[i] == want[i].id);
                    if (want[i].tri >= 0) CHECK(prim[i] == want[i].tri);
                    CHECK(closest.t_max[i] == want[i].t);  // the same bits: the same float arithmetic
                    CHECK((any.t_max[i] == 0.f) == (want[i].id >= 0));
                }
            });
        }
    }
}
