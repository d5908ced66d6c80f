#pragma once
// The SIMD intersection kernels, one per canonical shape and closest/any-hit, compiled for
// several x86-64 levels (kernels/isa_*.cpp) and picked once per render from what the CPU
// has. The pipeline calls them through this table, so only these files carry ISA flags.
#include <array>
#include <cstddef>
#include <cstdint>

#include "core/enum_names.h"
#include <string>
#include <vector>

#include "kernels/csg_view.h"
#include "kernels/kernel_object.h"
#include "kernels/shade_job.h"
#include "mesh/mesh_view.h"
#include "scene/scene.h"
#include "kernels/ray_stream.h"

namespace streamrt {

/// Closest hit: for each ray, shrinks t_max to the nearest hit among objs and writes that
/// object's id into object[]. Rays that hit nothing keep t_max and object untouched. Mesh
/// kernels also write the triangle and its barycentrics into rays.prim/bu/bv (when given)
/// whenever they find a closer hit, so those hold the winning mesh hit's values.
using ClosestHitFn = void (*)(RayView rays, std::int32_t* object, const ObjectXf* objs, std::size_t n_objs);
/// Any hit (shadow rays): sets t_max to 0 for every ray blocked by one of objs; packets whose
/// rays are all blocked already are skipped.
using AnyHitFn = void (*)(RayView rays, const ObjectXf* objs, std::size_t n_objs);

/// The same with a bounding box per object (bounds[k] for objs[k]), tested per packet.
using ClosestCulledFn = void (*)(RayView rays, std::int32_t* object, const ObjectXf* objs, const ObjectBounds* bounds,
                                 std::size_t n_objs);
using AnyCulledFn = void (*)(RayView rays, const ObjectXf* objs, const ObjectBounds* bounds, std::size_t n_objs);

enum class Isa : std::uint8_t { Sse2, Sse42, Avx2, Avx512 };
inline constexpr int kIsaCount = 4;
inline constexpr EnumName<Isa> kIsaNames[] = {
    {Isa::Sse2, "sse2"}, {Isa::Sse42, "sse4.2"}, {Isa::Avx2, "avx2"}, {Isa::Avx512, "avx512"}};

struct KernelTable {
    Isa isa;
    const char* name;
    int float_lanes;
    ClosestHitFn closest[kShapeKindCount];
    AnyHitFn any[kShapeKindCount];
    ClosestCulledFn closest_culled[kShapeKindCount];
    AnyCulledFn any_culled[kShapeKindCount];
    std::array<ShadeFn, kShadeVariants> shade;
    std::array<ShadeFn, kShadeVariants> shade_gathered;  ///< runs of one material and kind, objects per lane
    GenerateFn generate;
    GenerateFn generate_lens;  ///< thin-lens cameras (aperture > 0) only
    CsgClosestFn csg_closest;  ///< scenes with CSG objects only (stream/stream_csg.h)
    CsgAnyFn csg_any;
};

/// The best level this CPU runs.
Isa best_isa();
bool isa_supported(Isa isa);
const char* isa_name(Isa isa);
/// Parses "sse2", "sse4.2", "avx2", "avx512"; false if unknown.
bool parse_isa(const std::string& s, Isa& out);
/// The kernels built for that level (the caller has checked isa_supported).
const KernelTable& kernel_table(Isa isa);

namespace isa_kernels {
// Defined in kernels/isa_<level>.cpp.
const KernelTable& sse2();
const KernelTable& sse42();
const KernelTable& avx2();
const KernelTable& avx512();
}  // namespace isa_kernels

}  // namespace streamrt
