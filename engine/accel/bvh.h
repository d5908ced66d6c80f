#pragma once
// A bounding volume hierarchy with 8-wide nodes: built top-down with the binned surface area
// heuristic (in parallel with oneTBB through parallel/parallelism.h), then collapsed from a
// binary tree into nodes of up to 8 children whose boxes sit as structure-of-arrays, so that
// one SIMD operation tests a ray against all of them (kernels/accel_kernel.h), or one child
// against a packet of rays.
//
// The hierarchy knows only boxes and primitive indices (the scene's objects, scene/scene_bvh.h;
// a mesh's triangles could be primitives of another).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "core/vec3.h"
#include "simd/lanes.h"

namespace streamrt::accel {

struct Aabb {
    float lo[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                   std::numeric_limits<float>::infinity()};
    float hi[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                   -std::numeric_limits<float>::infinity()};

    bool empty() const { return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]); }
    void grow(const Aabb& b) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], b.lo[a]);
            hi[a] = std::max(hi[a], b.hi[a]);
        }
    }
    void grow(const float p[3]) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], p[a]);
            hi[a] = std::max(hi[a], p[a]);
        }
    }
    float centre(int a) const { return 0.5f * (lo[a] + hi[a]); }
    /// Half the surface area (the SAH only compares ratios).
    float half_area() const {
        if (empty()) return 0.f;
        const float x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
        return x * y + y * z + z * x;
    }
};

/// The box of double-precision bounds, rounded outwards to float and padded by a few ulps of
/// its extent, so a float slab test can never reject a ray that touches the true shape.
Aabb conservative_box(const double lo[3], const double hi[3]);

inline constexpr int kNodeWidth = 8;

/// One 8-wide node, 256 bytes. Child j is empty (child = -1, box lo > hi, never hit), an
/// inner node (count = 0, child = node index) or a leaf (count > 0, primitives
/// prim_index[child .. child + count)).
struct alignas(64) WideNode {
    float lo_x[kNodeWidth], lo_y[kNodeWidth], lo_z[kNodeWidth];
    float hi_x[kNodeWidth], hi_y[kNodeWidth], hi_z[kNodeWidth];
    std::int32_t child[kNodeWidth];
    std::uint32_t count[kNodeWidth];
};
static_assert(sizeof(WideNode) == 256);

struct BuildOptions {
    int max_leaf = 4;        ///< largest leaf the SAH may choose
    int bins = 16;           ///< bins per axis
    float traversal_cost = 3.f;  ///< node visit, relative to one primitive test (measured: 3 beats 1)
    /// The collapse into 8-wide nodes (bvh.cpp, Collapser): one child box test, relative to
    /// the rest of a node visit.
    float wide_child_cost = 0.1f;
    std::size_t parallel_grain = 4096;  ///< subtrees at least this big are built as parallel tasks
};

struct BuildStats {
    double seconds = 0;
    std::size_t binary_nodes = 0, wide_nodes = 0, leaves = 0;
    int depth = 0;  ///< levels of wide nodes on the longest path from the root (the root alone: 1; empty: 0)
};

/// The hierarchy over a set of primitive boxes. Node 0 is the root; an empty hierarchy has no
/// nodes. prim_index maps leaf order back to the caller's primitive numbers.
struct Bvh {
    simd::AlignedVec<WideNode> nodes;
    std::vector<std::uint32_t> prim_index;
    Aabb bounds;
    BuildStats stats;

    bool empty() const { return nodes.empty(); }
    std::size_t memory_bytes() const {
        return nodes.size() * sizeof(WideNode) + prim_index.size() * sizeof(std::uint32_t);
    }
    /// Builds over boxes (empty boxes are left out). Taken by value: pass them with std::move
    /// and their memory is given back before the build proper starts.
    static Bvh build(std::vector<Aabb> boxes, const BuildOptions& options = {});
    /// The same over primitives 0 .. n-1 whose boxes box_of(k) gives (called once each, from
    /// several threads): no array of boxes is made, so a large mesh touches less memory.
    static Bvh build(std::size_t n, const std::function<Aabb(std::size_t)>& box_of, const BuildOptions& options = {});
};

/// What refitting a hierarchy needs beside it (animation, scene/animation.h): each node's
/// parent and its slot there, and the leaf holding each primitive position. Built on the
/// first refit only, so a still scene never pays for it.
struct BvhLinks {
    std::vector<std::int32_t> parent;     ///< per node; -1 for the root
    std::vector<std::uint8_t> slot;       ///< per node: its slot in the parent
    std::vector<std::int32_t> leaf_node;  ///< per primitive position: the node with its leaf
    std::vector<std::uint8_t> leaf_slot;  ///< ... and the slot of that leaf
    BvhLinks(const Bvh& bvh, std::size_t prims);
};

/// Refits the hierarchy after some primitives moved: each leaf holding one of the positions
/// `moved` gets the union of its primitives' boxes (box(position) for each), then every box
/// above a changed leaf is recomputed from its node's children, deepest nodes first. The
/// tree keeps its shape (a refit is exact, it may only be slower to traverse than a rebuild
/// when objects moved far).
void refit(Bvh& bvh, const BvhLinks& links, std::span<const std::uint32_t> moved,
           const std::function<Aabb(std::uint32_t)>& box);

/// Scalar slab test of one ray against child j of a node, t in [0, t_max]. inv is 1/d per
/// component. NaN slab distances (0 * inf for a ray on a slab plane) are ignored, so a
/// grazing ray counts as a hit (conservative).
template <class T>
inline bool child_hit(const WideNode& n, int j, const Vec3T<T>& o, const Vec3T<T>& inv, T t_max, T& t_near) {
    T tn = T(0), tf = t_max;
    const auto slab = [&](float lo, float hi, T oc, T ic) {
        const T a = (T(lo) - oc) * ic, b = (T(hi) - oc) * ic;
        const T mn = a < b ? a : b, mx = a < b ? b : a;
        tn = mn > tn ? mn : tn;
        tf = mx < tf ? mx : tf;
    };
    slab(n.lo_x[j], n.hi_x[j], o.x, inv.x);
    slab(n.lo_y[j], n.hi_y[j], o.y, inv.y);
    slab(n.lo_z[j], n.hi_z[j], o.z, inv.z);
    t_near = tn;
    return tn <= tf && n.child[j] >= 0;
}

/// Scalar closest-hit traversal (the baseline's): front to back, children sorted by entry
/// distance. leaf(first, count, t_max) tests prim_index[first .. first + count) and shrinks
/// t_max to the nearest hit it finds.
template <class T, class Leaf>
void traverse_closest(const Bvh& bvh, const Vec3T<T>& o, const Vec3T<T>& d, T& t_max, Leaf&& leaf) {
    if (bvh.empty()) return;
    const Vec3T<T> inv{T(1) / d.x, T(1) / d.y, T(1) / d.z};
    struct Entry {
        std::int32_t child;
        std::uint32_t count;
        T t;
    };
    Entry stack[kNodeWidth * 64];
    int sp = 0;
    stack[sp++] = {0, 0, T(0)};
    while (sp > 0) {
        const Entry e = stack[--sp];
        if (e.t > t_max) continue;
        if (e.count > 0) {
            leaf(std::uint32_t(e.child), e.count, t_max);
            continue;
        }
        const WideNode& n = bvh.nodes[std::size_t(e.child)];
        Entry hits[kNodeWidth];
        int nh = 0;
        for (int j = 0; j < kNodeWidth; ++j) {
            T tn;
            if (child_hit(n, j, o, inv, t_max, tn)) {
                // insertion sort, farthest first, so the nearest is pushed last
                int k = nh++;
                while (k > 0 && hits[k - 1].t < tn) {
                    hits[k] = hits[k - 1];
                    --k;
                }
                hits[k] = {n.child[j], n.count[j], tn};
            }
        }
        for (int k = 0; k < nh; ++k) stack[sp++] = hits[k];
    }
}

/// Scalar any-hit traversal: true as soon as leaf(first, count, t_max) returns true.
template <class T, class Leaf>
bool traverse_any(const Bvh& bvh, const Vec3T<T>& o, const Vec3T<T>& d, T t_max, Leaf&& leaf) {
    if (bvh.empty()) return false;
    const Vec3T<T> inv{T(1) / d.x, T(1) / d.y, T(1) / d.z};
    std::int32_t stack[kNodeWidth * 64];
    std::uint32_t counts[kNodeWidth * 64];
    int sp = 0;
    stack[sp] = 0;
    counts[sp++] = 0;
    while (sp > 0) {
        --sp;
        const std::int32_t c = stack[sp];
        const std::uint32_t cnt = counts[sp];
        if (cnt > 0) {
            if (leaf(std::uint32_t(c), cnt, t_max)) return true;
            continue;
        }
        const WideNode& n = bvh.nodes[std::size_t(c)];
        for (int j = 0; j < kNodeWidth; ++j) {
            T tn;
            if (child_hit(n, j, o, inv, t_max, tn)) {
                stack[sp] = n.child[j];
                counts[sp++] = n.count[j];
            }
        }
    }
    return false;
}

}  // namespace streamrt::accel
