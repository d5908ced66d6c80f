#pragma once
// Constructive solid geometry along one line (docs/architecture.md, "CSG"): each solid's span
// (shapes/solid_span.h), then the first point where the line crosses the result's surface,
// found by classifying points against the tree (csg_first_boundary). One template for both
// engines, scalar and in SIMD lanes, in fixed arrays (kMaxCsgShapes): nothing is allocated
// per ray.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>

#include "scene/scene.h"
#include "mesh/mesh_solid.h"
#include "render/csg_layout.h"
#include "mesh/mesh_trace.h"
#include "scene/scene_bvh.h"
#include "shapes/shapes.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// The spans of an object's slots along one line (t over the whole line), each empty unless
/// enter < exit (a miss: +inf, -inf; NaN compares as a miss).
template <class V>
struct CsgLine {
    std::array<V, kMaxCsgShapes> enter, exit;
};

/// A closed mesh's spans along a line from its crossings sorted along it (mesh_crossings):
/// where the count, +1 going in and -1 going out, is other than 0; the first kMeshCsgSpans
/// into enter[s * stride], exit[s * stride] and ends[s * stride] for s = 0, 1, ..., the other
/// spans empty. A count left open at the last crossing (a line that rounding let through an
/// edge) closes nothing.
template <class V>
void mesh_winding_spans(const MeshCrossing<V>* c, int n, V* enter, V* exit, CsgSlotEnds* ends, std::size_t stride) {
    for (std::size_t j = 0; j < std::size_t(kMeshCsgSpans); ++j) {
        enter[j * stride] = std::numeric_limits<V>::infinity();
        exit[j * stride] = -std::numeric_limits<V>::infinity();
    }
    int winding = 0;
    std::size_t span = 0;
    for (int i = 0; i < n && span < std::size_t(kMeshCsgSpans); ++i) {
        const int before = winding;
        winding += c[i].enters ? 1 : -1;
        const std::size_t j = span * stride;
        if (before == 0 && winding != 0) {
            enter[j] = c[i].t;  // a span left open keeps exit -inf: empty
            ends[j].tri[0] = c[i].tri;
            ends[j].turned[0] = !c[i].enters;  // going in, the surface faces along the line
        } else if (before != 0 && winding == 0) {
            exit[j] = c[i].t;
            ends[j].tri[1] = c[i].tri;
            ends[j].turned[1] = c[i].enters;
            ++span;
        }
    }
}

/// A closed mesh's spans along the line o + t d (its canonical space) into its slots
/// [first, first + kMeshCsgSpans) (mesh_winding_spans).
template <class V>
void mesh_slot_spans(CsgLine<V>& line, CsgSlotEnds* ends, int first, const Mesh& mesh, const Vec3T<V>& o,
                     const Vec3T<V>& d) {
    MeshCrossing<V> c[kMeshCsgCrossings];
    const int n = mesh_crossings(mesh.view(), mesh.bvh, o, d, c, kMeshCsgCrossings);
    const auto j = std::size_t(first);
    mesh_winding_spans(c, n, &line.enter[j], &line.exit[j], ends + j, 1);
}

/// A torus's spans along the line o + t d (its canonical space) into its slots [first,
/// first + 2): torus_spans, solved in double in every engine (as the torus always is) and
/// rounded to V.
template <class V>
void torus_slot_spans(CsgLine<V>& line, int first, const Vec3T<V>& o, const Vec3T<V>& d, V minor) {
    const auto wide = [](const Vec3T<V>& v) { return Vec3T<double>{double(v.x), double(v.y), double(v.z)}; };
    const std::array<SpanT<double>, 2> s = torus_spans<double>(wide(o), wide(d), double(minor));
    for (std::size_t j = 0; j < 2; ++j) {
        line.enter[std::size_t(first) + j] = V(s[j].enter);
        line.exit[std::size_t(first) + j] = V(s[j].exit);
    }
}

/// Where a line first crosses a CSG result's surface (csg_first_boundary), per lane.
template <class V>
struct CsgFirst {
    using M = decltype(std::declval<V>() < std::declval<V>());
    V t;          ///< +inf: none in (t_min, t_max)
    V slot;       ///< the slot whose end it is
    M at_exit;    ///< the slot's exit (else its enter)
    M entering;   ///< the line goes into the result there (else out of it)
};

/// Per lane a ? b : c, for masks (bool or a batch's).
template <class M>
M mask_select(const M& a, const M& b, const M& c) {
    return (a && b) || (!a && c);
}

template <class M>
M csg_node_inside(const CsgNode* nodes, std::uint32_t node, const CsgSlotLayout& layout, const M* in_slot);

/// Whether the points of the line where in_slot holds (per slot) are inside child `c` of a
/// node: a nested node's result, or a shape's (any of its slots).
template <class M>
[[gnu::always_inline]] inline M csg_child_inside(const CsgNode* nodes, const CsgNode::Child& c, const CsgSlotLayout& layout,
                                                 const M* in_slot) {
    if (c.is_node) return csg_node_inside(nodes, c.index, layout, in_slot);
    M m(false);
    const std::size_t s = c.index - layout.first_shape;
    for (int j = layout.first_slot[s]; j < layout.first_slot[s + 1]; ++j) m = m || in_slot[j];
    return m;
}

/// Whether the points of the line where in_slot holds (per slot) are in the result of node
/// `node`: a union (and a merge) of its children, an intersection, or the first child minus
/// the others.
template <class M>
M csg_node_inside(const CsgNode* nodes, std::uint32_t node, const CsgSlotLayout& layout, const M* in_slot) {
    const CsgNode& n = nodes[node];
    M r(false);
    bool first = true;
    for (const CsgNode::Child& c : n.children) {
        const M m = csg_child_inside(nodes, c, layout, in_slot);
        if (first) {
            r = m;
            first = false;
            continue;
        }
        switch (n.op) {
            case CsgOp::Intersection: r = r && m; break;
            case CsgOp::Difference: r = r && !m; break;
            case CsgOp::Union:
            case CsgOp::Merge: r = r || m; break;
        }
    }
    return r;
}

/// Whether the tree at `root` shows inner surfaces: a `union` that is not inside an odd number
/// of subtracted children (a subtracted union is an intersection of what it leaves, which has
/// none). Trees without one take the walk's plain rule: a surface where the class changes.
inline bool csg_shows_inner_surfaces(const CsgNode* nodes, std::uint32_t node, bool inverted = false) {
    const CsgNode& n = nodes[node];
    if (n.op == CsgOp::Union && !inverted) return true;
    for (std::size_t i = 0; i < n.children.size(); ++i) {
        const bool subtracted = n.op == CsgOp::Difference && i > 0;
        if (n.children[i].is_node && csg_shows_inner_surfaces(nodes, n.children[i].index, inverted != subtracted))
            return true;
    }
    return false;
}

/// A step of the walk at a surface of a node's result, per lane: whether one is there, and
/// whether the line goes into the solid it bounds (seen from the result's side).
template <class M>
struct CsgSurface {
    M visible, entering;
};

/// Whether node `node` shows a surface at a step of the walk from the slots' classes before
/// it to those after (POV-Ray's rules): where its class changes, and, where it does not, a
/// child's own surface that the node keeps: a `union` keeps every child's (its inner
/// surfaces) unless it is subtracted (`inverted`), any other node a child's only where each
/// of the other children is, on both sides of the point, in the state that lets the child's
/// class decide the node's (inside for an intersection, outside for a union or merge; for a
/// difference the first child inside and the others outside). Such a filtered surface of a
/// plain shape is a class change already: only nested unions add surfaces. Ties: the first
/// child (in written order) that shows one gives `entering`.
template <class M>
CsgSurface<M> csg_node_surface(const CsgNode* nodes, std::uint32_t node, const CsgSlotLayout& layout,
                               const M* before, const M* after, bool inverted) {
    const CsgNode& n = nodes[node];
    const M now = csg_node_inside(nodes, node, layout, after);
    CsgSurface<M> r{simd::mask_xor(csg_node_inside(nodes, node, layout, before), now), now};
    const bool keeps_all = n.op == CsgOp::Union && !inverted;
    const auto child_inside = [&](std::size_t i, const M* in) {
        return csg_child_inside(nodes, n.children[i], layout, in);
    };
    for (std::size_t i = 0; i < n.children.size(); ++i) {
        const CsgNode::Child& c = n.children[i];
        if (!keeps_all && !c.is_node) continue;  // a class change of this node if kept
        const bool subtracted = n.op == CsgOp::Difference && i > 0;
        CsgSurface<M> cs;
        if (c.is_node) {
            cs = csg_node_surface(nodes, c.index, layout, before, after, inverted != subtracted);
        } else {
            const M in = child_inside(i, after);
            cs = {simd::mask_xor(child_inside(i, before), in), in};
        }
        M take = cs.visible && !r.visible;
        if (!simd::any(take)) continue;
        for (std::size_t k = 0; k < n.children.size() && !keeps_all; ++k) {
            if (k == i) continue;
            // The state sibling k must hold on both sides.
            const bool want_inside = n.op == CsgOp::Intersection || (n.op == CsgOp::Difference && k == 0);
            const M b = child_inside(k, before), a = child_inside(k, after);
            take = take && (want_inside ? (b && a) : !(b || a));
        }
        r.entering = mask_select(take, subtracted ? !cs.entering : cs.entering, r.entering);
        r.visible = r.visible || take;
    }
    return r;
}

/// The first point of the line in (t_min, t_max) where it goes into or out of the result of
/// the tree at `root`: one definition for both engines, scalar (V = double, float) and in
/// lanes (V = a batch). A point is in a slot's span when enter <= t < exit (so a span of length
/// 0 holds nothing), and the walk steps from t_min to each next end of a span, classifying the
/// point just after it by the tree (csg_node_inside): the first step whose class differs from
/// the one before is the boundary. Where ends of several slots coincide, the class is taken
/// after all of them (a subtracted face lying on the base's face removes it; spans that touch
/// join), and the surface shown is the lowest slot's among them: the first-written shape's
/// (docs/scene-format.md, "CSG"). `live`: the slots to read, ascending (the others are empty
/// in every lane). No sorting and no lists: at most one step per span end. `inner_surfaces`
/// (csg_shows_inner_surfaces of the tree): a step is also a boundary where a union keeps a
/// child's surface inside the result (csg_node_surface), `entering` then that child's.
template <class V>
CsgFirst<V> csg_first_boundary(const CsgNode* nodes, std::uint32_t root, const CsgSlotLayout& layout,
                               const CsgLine<V>& line, const std::uint8_t* live, int live_count, const V& t_min,
                               const V& t_max, bool inner_surfaces = false) {
    using M = typename CsgFirst<V>::M;
    using S = simd::scalar_t<V>;
    const V inf(std::numeric_limits<S>::infinity());
    std::array<M, kMaxCsgShapes> in, valid, before;
    for (int j = 0; j < layout.slots(); ++j) in[std::size_t(j)] = before[std::size_t(j)] = M(false);
    for (int i = 0; i < live_count; ++i) {
        const std::size_t s = live[i];
        valid[std::size_t(i)] = line.enter[s] < line.exit[s];
        in[s] = valid[std::size_t(i)] && (line.enter[s] <= t_min) && (t_min < line.exit[s]);
    }
    M state = csg_node_inside(nodes, root, layout, in.data());
    CsgFirst<V> r{inf, V(S(0)), M(false), M(false)};
    M active = t_min < t_max;
    V at = t_min;
    while (true) {
        V next = inf;
        for (int i = 0; i < live_count; ++i) {
            const std::size_t s = live[i];
            const M v = valid[std::size_t(i)];
            next = simd::min(next, simd::select(v && (line.enter[s] > at), line.enter[s], inf));
            next = simd::min(next, simd::select(v && (line.exit[s] > at), line.exit[s], inf));
        }
        active = active && (next < t_max);
        if (!simd::any(active)) break;
        for (int i = 0; i < live_count; ++i) {
            const std::size_t s = live[i];
            if (inner_surfaces) before[s] = in[s];
            in[s] = valid[std::size_t(i)] && (line.enter[s] <= next) && (next < line.exit[s]);
        }
        const M now = csg_node_inside(nodes, root, layout, in.data());
        M change = active && simd::mask_xor(now, state), entering = now;
        if (inner_surfaces) {
            // A kept inner surface lies inside the result on both sides of it (a union's
            // child's surface inside another child, or one its siblings hold inside): only
            // such steps ask the tree, so a line from outside pays nothing up to its way in.
            const M inside = active && now && state;
            if (simd::any(inside)) {
                const CsgSurface<M> surface = csg_node_surface(nodes, root, layout, before.data(), in.data(), false);
                const M inner = inside && surface.visible;
                entering = mask_select(inner, surface.entering, entering);
                change = change || inner;
            }
        }
        if (simd::any(change)) {
            V slot(S(0));
            M at_exit(false);
            for (int i = live_count - 1; i >= 0; --i) {  // the lowest slot last
                const std::size_t s = live[i];
                const M v = valid[std::size_t(i)];
                const M ends_exit = v && (line.exit[s] == next), here = (v && (line.enter[s] == next)) || ends_exit;
                slot = simd::select(here, V(S(s)), slot);
                at_exit = mask_select(here, ends_exit, at_exit);
            }
            r.t = simd::select(change, next, r.t);
            r.slot = simd::select(change, slot, r.slot);
            r.at_exit = mask_select(change, at_exit, r.at_exit);
            r.entering = mask_select(change, entering, r.entering);
            active = active && !change;
            if (!simd::any(active)) break;
        }
        state = now;
        at = next;
    }
    return r;
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

/// One line's spans through every shape of an object, in scalar code (V = float, double):
/// `canonical(shape)` gives the line (o, d) in the shape's canonical space, `solid(shape)` its
/// kind, parameter and mesh (null for other kinds). Fills `line` and `ends` (a mesh's; a
/// convex shape's plain), and `live` with the slots the line meets, ascending; returns their
/// count.
template <class V, class Canonical, class Solid>
int csg_scalar_line(const CsgSlotLayout& layout, const Canonical& canonical, const Solid& solid, CsgLine<V>& line,
                    CsgSlotEnds* ends, std::uint8_t* live) {
    int n = 0;
    for (int s = 0; s < layout.shapes; ++s) {
        const std::uint32_t shape = layout.first_shape + std::uint32_t(s);
        const auto [o, d] = canonical(shape);
        const auto [kind, param, mesh] = solid(shape);
        const int j = layout.first_slot[std::size_t(s)];
        if (mesh) {
            mesh_slot_spans(line, ends, j, *mesh, o, d);
        } else if (kind == ShapeKind::Torus) {
            torus_slot_spans(line, j, o, d, V(param));
            ends[j] = ends[j + 1] = CsgSlotEnds{};
        } else {
            const SpanT<V> span = csg_shape_span(kind, o, d, V(param));
            line.enter[std::size_t(j)] = span.enter;
            line.exit[std::size_t(j)] = span.exit;
            ends[j] = CsgSlotEnds{};
        }
        for (int i = j; i < layout.first_slot[std::size_t(s) + 1]; ++i)
            if (line.enter[std::size_t(i)] < line.exit[std::size_t(i)]) live[n++] = std::uint8_t(i);
    }
    return n;
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
