#pragma once
// CSG objects whose surfaces are worked out by hand, for both engines' tests (csg_test.cpp,
// csg_stream_test.cpp).

#include <limits>

#include "baseline/recursive_renderer.h"
#include "scene/scene.h"

namespace streamrt::csg_cases {

/// The recursive engine's closest hit of the ray from `from` along unit `dir`, past t_min;
/// false on a miss.
inline bool hit_of(const Scene& scene, Vec3d from, Vec3d dir, HitD& hit, double t_min = 0.0) {
    const RecursiveRenderer r(scene);
    return r.closest_hit(RayD{from, dir}, t_min, std::numeric_limits<double>::infinity(), hit);
}

// A biconvex lens: spheres of radius 2 centred at z = -1.5 and z = +1.5, intersected. Along the
// axis it spans z in [-0.5, 0.5]; at x = 1 it spans |z| <= sqrt(3) - 1.5.
inline const char* const kLens =
    "csg intersection\n"
    "  sphere scale=2,2,2 translate=0,0,-1.5\n"
    "  sphere scale=2,2,2 translate=0,0,1.5\n"
    "end\n";

// A pipe: a cylinder of radius 1 and height 4 minus a longer one of radius 0.8.
inline const char* const kPipe =
    "csg difference\n"
    "  cylinder scale=1,2,1\n"
    "  cylinder scale=0.8,2.1,0.8\n"
    "end\n";

// A die with one dimple: the cube [-1,1]^3 minus a sphere of radius 0.5 at z = 1.2, which cuts
// a cap of depth 0.3 into the face z = 1.
inline const char* const kDie =
    "csg difference\n"
    "  cube\n"
    "  sphere scale=0.5,0.5,0.5 translate=0,0,1.2\n"
    "end\n";

// Two unit spheres centred at x = -0.5 and x = +0.5, a block's children: along the x axis the
// first spans [-1.5, 0.5], the second [-0.5, 1.5].
inline const char* const kTwoSpheres =
    "  sphere translate=-0.5,0,0\n"
    "  sphere translate=0.5,0,0\n";

// A ring with a bite: a torus (tube radius 0.5) minus a sphere of radius 0.3 centred on the
// tube's circle at x = 1. Along the x axis the torus spans [-1.5, -0.5] and [0.5, 1.5], the
// sphere [0.7, 1.3].
inline const char* const kRingCut =
    "csg difference\n"
    "  torus minor=0.5\n"
    "  sphere scale=0.3 translate=1,0,0\n"
    "end\n";

}  // namespace streamrt::csg_cases
