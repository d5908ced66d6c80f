#pragma once
// Constructive solid geometry along one line (docs/architecture.md, "CSG"): each solid's span
// (shapes/solid_span.h) combined node by node into the spans of the result. Scalar code for
// both engines, in fixed arrays (kMaxCsgShapes): nothing is allocated per ray.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "scene/scene.h"
#include "mesh/mesh_solid.h"
#include "mesh/mesh_trace.h"
#include "scene/scene_bvh.h"
#include "shapes/shapes.h"
#include "simd/isa_namespace.h"

namespace streamrt {

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// One end of a span: where the line crosses the surface of shape `shape` (an index in
/// Scene::csg_shapes), and whether that surface's normal points into the result (a subtracted
/// shape's surface: the normal shown must be turned round).
template <class V>
struct CsgBoundary {
    V t;
    std::uint32_t shape;
    bool flip;
    std::uint32_t tri = 0;  ///< a mesh's triangle there (leaf order); 0 for other shapes
};

/// A node's spans along the line, sorted and disjoint: [b[0], b[1]], [b[2], b[3]], ... each
/// of positive length (a zero-length one, from a tangent line or coinciding surfaces, is
/// dropped: it bounds nothing).
template <class V>
struct CsgSpans {
    std::array<CsgBoundary<V>, 2 * kMaxCsgShapes> b;
    int size = 0;  ///< boundaries: twice the spans

    void open(const CsgBoundary<V>& at) { b[std::size_t(size++)] = at; }
    void close(const CsgBoundary<V>& at) {
        if (at.t > b[std::size_t(size - 1)].t) b[std::size_t(size++)] = at;
        else --size;
    }
    void assign(const CsgSpans& other) {
        size = other.size;
        for (int i = 0; i < size; ++i) b[std::size_t(i)] = other.b[std::size_t(i)];
    }
};

/// Whether a point is in the result of op, from whether it is in each operand.
constexpr bool csg_inside(CsgOp op, bool in_a, bool in_b) {
    switch (op) {
        case CsgOp::Intersection: return in_a && in_b;
        case CsgOp::Difference: return in_a && !in_b;
        case CsgOp::Union:
        case CsgOp::Merge: break;
    }
    return in_a || in_b;
}

/// out = a op b: one sweep over both lists' boundaries in order of t. Where a boundary of a and
/// one of b coincide, a's is taken first (docs/scene-format.md, "CSG", coinciding surfaces).
template <class V>
void combine_spans(CsgOp op, const CsgSpans<V>& a, const CsgSpans<V>& b, CsgSpans<V>& out) {
    out.size = 0;
    bool in_a = false, in_b = false, in_out = false;
    int ia = 0, ib = 0;
    const bool b_is_removed = op == CsgOp::Difference;  // its surfaces face into the result
    while (ia < a.size || ib < b.size) {
        CsgBoundary<V> at;
        if (ib == b.size || (ia < a.size && !(b.b[std::size_t(ib)].t < a.b[std::size_t(ia)].t))) {
            at = a.b[std::size_t(ia++)];
            in_a = !in_a;
        } else {
            at = b.b[std::size_t(ib++)];
            at.flip = at.flip != b_is_removed;
            in_b = !in_b;
        }
        const bool now = csg_inside(op, in_a, in_b);
        if (now == in_out) continue;
        if (now) out.open(at);
        else out.close(at);
        in_out = now;
    }
}

/// A convex solid's (or a half-space's) span as a span list: none for a miss (NaN included)
/// or a span of length 0 (a tangent line).
template <class V>
void add_solid_span(CsgSpans<V>& into, const SpanT<V>& s, std::uint32_t shape) {
    if (s.enter < s.exit) {
        into.open({s.enter, shape, false});
        into.close({s.exit, shape, false});
    }
}

/// A closed mesh's spans along the line o + t d (its canonical space): where the crossings,
/// counted +1 going in and -1 going out, add up to other than 0 (a mesh turned inside out is
/// a solid too, its normals turned round to face out of it: flip). At most kMeshCsgSpans, the
/// first along the line; a count left open at the last crossing (a line that rounding let
/// through an edge) closes nothing.
template <class V>
void add_mesh_spans(CsgSpans<V>& into, const Mesh& mesh, const Vec3T<V>& o, const Vec3T<V>& d, std::uint32_t shape) {
    MeshCrossing<V> c[kMeshCsgCrossings];
    const int n = mesh_crossings(mesh.view(), mesh.bvh, o, d, c, kMeshCsgCrossings);
    int winding = 0, spans = 0;
    for (int i = 0; i < n && spans < kMeshCsgSpans; ++i) {
        const int before = winding;
        winding += c[i].enters ? 1 : -1;
        // Going in, the surface must face against the line: a triangle facing along it is turned round.
        if (before == 0 && winding != 0) into.open({c[i].t, shape, !c[i].enters, c[i].tri});
        else if (before != 0 && winding == 0) {
            into.close({c[i].t, shape, c[i].enters, c[i].tri});
            spans = into.size / 2;
        }
    }
    if (into.size % 2 != 0) --into.size;  // an open span at the end: dropped
}

/// The spans of node `node` of a scene's CSG trees (`nodes`: Scene::csg_nodes) along a line.
/// leaf(k, into) writes the span list of Scene::csg_shapes[k] along the same line (in the same
/// units of t) into `into`, which it finds empty; a leaf(k) that returns the shape's SpanT
/// does as well.
template <class V, class Leaf>
void csg_node_spans(const CsgNode* nodes, std::uint32_t node, const Leaf& leaf, CsgSpans<V>& out) {
    const CsgNode& n = nodes[node];
    CsgSpans<V> child, combined;
    bool first = true;
    for (const CsgNode::Child& c : n.children) {
        CsgSpans<V>& into = first ? out : child;
        if (c.is_node) {
            csg_node_spans(nodes, c.index, leaf, into);
        } else {
            into.size = 0;
            if constexpr (std::is_invocable_v<const Leaf&, std::uint32_t, CsgSpans<V>&>) leaf(c.index, into);
            else add_solid_span(into, leaf(c.index), c.index);
        }
        if (first) {
            first = false;
        } else if (child.size == 0) {
            // A child the line misses removes nothing and adds nothing (the sweep would give
            // `out` back unchanged); an intersection with it is empty. Most of a die's dimples
            // miss most rays: this saves their sweeps.
            if (n.op == CsgOp::Intersection) out.size = 0;
        } else {
            combine_spans(n.op, out, child, combined);
            out.assign(combined);
        }
        // Nothing left stays nothing: the other children cannot add to it.
        if (out.size == 0 && (n.op == CsgOp::Intersection || n.op == CsgOp::Difference)) return;
    }
}

/// The first boundary with t_min < t < t_max (an infinite end is no surface), or null.
template <class V>
const CsgBoundary<V>* first_boundary(const CsgSpans<V>& spans, V t_min, V t_max) {
    for (int i = 0; i < spans.size; ++i) {
        const CsgBoundary<V>& at = spans.b[std::size_t(i)];
        if (at.t > t_min) return at.t < t_max ? &at : nullptr;
    }
    return nullptr;
}

/// A CSG shape's span in its canonical space (o, d: the line there); a kind that is no solid
/// (the reader refuses those) spans nothing.
template <class V>
SpanT<V> csg_shape_span(ShapeKind kind, const Vec3T<V>& o, const Vec3T<V>& d, V param) {
    if (kind == ShapeKind::Mesh) return {V(1), V(0)};
    return visit_shape(kind, [&](auto shape) -> SpanT<V> {
        if constexpr (Solid<decltype(shape)>) return solid_span<decltype(shape)>(o, d, param);
        else return {V(1), V(0)};
    });
}

/// A world box of a CSG result: lo > hi on an axis when it is empty, infinite ends where it
/// is unbounded.
struct CsgBox {
    double lo[3], hi[3];

    bool empty() const { return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]); }
    bool bounded() const {
        return std::isfinite(lo[0] + lo[1] + lo[2]) && std::isfinite(hi[0] + hi[1] + hi[2]);
    }
};

/// The world box of node `node`'s result: a union's (and a merge's) holds its children's
/// boxes, an intersection's is their overlap, a difference's is its first child's (what is
/// removed adds nothing). A shape without bounds (the plane's half-space) is unbounded.
inline CsgBox csg_node_box(const Scene& scene, std::uint32_t node) {
    const CsgNode& n = scene.csg_nodes[node];
    constexpr double kInf = std::numeric_limits<double>::infinity();
    CsgBox box{};
    for (std::size_t i = 0; i < n.children.size(); ++i) {
        const CsgNode::Child& c = n.children[i];
        CsgBox child{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
        if (c.is_node) child = csg_node_box(scene, c.index);
        else accel::object_world_bounds(scene.csg_shapes[c.index], scene.mesh_of(scene.csg_shapes[c.index]), child.lo, child.hi);
        if (i == 0) {
            box = child;
            if (n.op == CsgOp::Difference) break;
            continue;
        }
        const bool overlap = n.op == CsgOp::Intersection;
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = overlap ? std::max(box.lo[a], child.lo[a]) : std::min(box.lo[a], child.lo[a]);
            box.hi[a] = overlap ? std::min(box.hi[a], child.hi[a]) : std::max(box.hi[a], child.hi[a]);
        }
    }
    return box;
}

/// False when the ray o + t d surely stays out of `box` for t in (t_min, t_max), so the
/// object inside needs no spans. The box is taken as an image of the canonical cube and met
/// through the cube's own span, widened by a millionth so that rounding never culls a shape
/// that touches its box; an unbounded or flat box culls nothing.
template <class V>
bool ray_may_meet(const CsgBox& box, const Vec3T<V>& o, const Vec3T<V>& d, V t_min, V t_max) {
    if (box.empty()) return false;
    if (!box.bounded()) return true;
    V oc[3], dc[3];
    const V os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    for (int a = 0; a < 3; ++a) {
        const double centre = 0.5 * (box.lo[a] + box.hi[a]);
        const double half = 0.5 * (box.hi[a] - box.lo[a]) + 1e-6 * (box.hi[a] - box.lo[a] + std::abs(centre));
        if (!(half > 0)) return true;
        oc[a] = (os[a] - V(centre)) / V(half);
        dc[a] = ds[a] / V(half);
    }
    const SpanT<V> s = solid_span<CubeMath>(Vec3T<V>{oc[0], oc[1], oc[2]}, Vec3T<V>{dc[0], dc[1], dc[2]}, V(0));
    return s.enter <= s.exit && s.enter < t_max && s.exit > t_min;
}

STREAMRT_ISA_END
}  // namespace streamrt
