#pragma once
// The hierarchy over a scene's objects, shared by both engines: world-space bounds of each
// object (its canonical bounds through Md), the infinite planes kept outside, and the policy
// that decides when a scene is traced with the hierarchy and how the stream engine walks it.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "accel/bvh.h"
#include "scene/scene.h"

namespace streamrt::accel {

/// World-space bounds of an object in double; false for an unbounded one (the plane, an
/// empty mesh). `mesh` is the object's mesh (Scene::mesh_of), for Mesh objects.
bool object_world_bounds(const Object& o, const Mesh* mesh, double lo[3], double hi[3]);

/// How the stream engine walks the hierarchy for one class of rays.
enum class Traversal : std::uint8_t {
    Packet,  ///< a packet of SIMD-width rays per walk, children tested one at a time against all lanes
    Single,  ///< one ray per walk, the 8 child boxes of a node tested in one SIMD operation
};

enum class AccelMode : std::uint8_t {
    Auto,  ///< the hierarchy when the scene has at least `min_objects` bounded objects
    Bvh,   ///< always the hierarchy
    Flat,  ///< the handout's loop over every object (per shape kind in the stream engine)
};
inline constexpr EnumName<AccelMode> kAccelModeNames[] = {
    {AccelMode::Auto, "auto"}, {AccelMode::Bvh, "bvh"}, {AccelMode::Flat, "flat"}};

/// How a render uses the hierarchy: a value carried by EngineOptions::accel to both engines
/// (the command line's --accel, perf/ and the tests set it there; no process-wide copy).
struct AccelConfig {
    AccelMode mode = AccelMode::Auto;
    /// Measured (docs/performance.md, "## BVH"): below this many bounded objects the flat
    /// loops are as fast or faster.
    std::size_t min_objects = 8;
    Traversal primary = Traversal::Packet;
    Traversal secondary = Traversal::Packet;  ///< reflected and refracted rays (packets measured faster, docs/performance.md)
    Traversal shadow = Traversal::Packet;
    BuildOptions build;
    /// Animation (scene/animation.h): frames refit the hierarchy while the objects moved since
    /// it was built (summed over frames) are at most this share of its objects, and rebuild
    /// it otherwise (docs/performance.md, "## Animation"). 0: always rebuild.
    double refit_max_share = 0.25;
    /// Stream engine, meshes (--mesh-hybrid): a packet of reflected or refracted rays from
    /// generation kMeshHybridFromDepth on whose directions have scattered
    /// (scattered_packet_lanes, kernels/mesh_kernel.h) walks a mesh's tree as a packet until a
    /// stack entry is reached by at most this many live rays, then as single rays. 0: packets
    /// only. Measured (docs/performance.md, "A switch per ray generation"): 16 saves a fifth
    /// of the intersect time in a scanned glass mesh and costs nothing measurable elsewhere.
    std::uint32_t mesh_hybrid_lanes = 16;
};
/// The first ray generation (0: camera rays) that --mesh-hybrid applies to. Rays of the
/// first bounces still share most of their paths even when their directions have spread:
/// on the scanned glass bunny the packet walk was faster for generations 2 and 3 (4.1 and
/// 2.2 Mrays/s against the hybrid's 3.3 and 1.9), level at 4 and slower from 5 on (0.8 -
/// 1.1 against 1.0 - 1.2; docs/performance.md, "A switch per ray generation").
inline constexpr int kMeshHybridFromDepth = 4;

/// The hierarchy over the bounded objects of a scene plus the list of the others.
struct SceneBvh {
    Bvh bvh;                               ///< prim_index holds object indices
    std::vector<std::uint32_t> unbounded;  ///< objects tested separately (planes)
    std::size_t bounded = 0;               ///< objects in the hierarchy

    /// nullptr when the configuration says this scene is traced flat.
    /// shift: the hierarchy is built for the scene translated by -shift (the stream engine
    /// renders relative to the eye, stream/stream_scene.cpp) without copying the scene.
    static std::unique_ptr<SceneBvh> build_for(const Scene& scene, const AccelConfig& config,
                                               const glm::dvec3& shift = glm::dvec3(0.0));
    /// The hierarchy regardless of the mode.
    static std::unique_ptr<SceneBvh> build(const Scene& scene, const BuildOptions& options = {},
                                           const glm::dvec3& shift = glm::dvec3(0.0));

    // ---- animation: per-frame update (scene/animation.h) ----
    /// Whether moving `moved` more of the hierarchy's objects is refitted (true) or rebuilt:
    /// refitted while all the objects moved since the build, these included, are at most
    /// config.refit_max_share of the hierarchy's.
    bool refit_pays(std::size_t moved, const AccelConfig& config) const;
    /// Refits the boxes of the scene objects `moved` (scene indices; unbounded ones are
    /// skipped) at their current Md. `order` maps a leaf position to its scene index
    /// (bvh.prim_index, or the stream engine's copy of it); shift as in build().
    void refit(const Scene& scene, std::span<const std::uint32_t> moved, std::span<const std::uint32_t> order,
               const glm::dvec3& shift = glm::dvec3(0.0));

  private:
    std::unique_ptr<BvhLinks> links_;       ///< built on the first refit
    std::vector<std::uint32_t> position_;   ///< scene index -> leaf position (~0u: unbounded)
    std::size_t refitted_ = 0;              ///< objects moved by refits since the build (with repeats)
};

}  // namespace streamrt::accel
