#pragma once
// How a CSG object's shapes map to the spans the walk along a line reads
// (render/csg_spans.h): plain data shared by both engines and every ISA level.
#include <array>
#include <cstdint>

#include "mesh/mesh_solid.h"
#include "scene/scene.h"
#include "shapes/solid_span.h"

namespace streamrt {

/// How an object's shapes map to slots, one span along a line each: a convex shape or a
/// half-space has one slot, a torus two, a closed mesh kMeshCsgSpans (csg_slots_of). The
/// reader counts slots against kMaxCsgShapes, so an object's fit the fixed arrays below.
struct CsgSlotLayout {
    std::uint32_t first_shape = 0;  ///< the object's first shape (Scene::csg_shapes)
    int shapes = 0;
    /// Shape first_shape + s has the slots [first_slot[s], first_slot[s + 1]).
    std::array<std::uint8_t, kMaxCsgShapes + 1> first_slot{};
    /// Each slot's shape, relative to first_shape.
    std::array<std::uint8_t, kMaxCsgShapes> shape_of{};
    int slots() const { return first_slot[std::size_t(shapes)]; }
};

/// A mesh slot's two ends (0: enter, 1: exit): the triangle crossed, and whether that
/// triangle faces the other way from a convex shape's surface there (a mesh turned inside
/// out: its normal must be turned round as well). Convex shapes' slots: 0, false
/// (CsgSlotEnds{}). No default values: the walk's arrays of them are filled per line, not
/// cleared.
struct CsgSlotEnds {
    std::array<std::uint32_t, 2> tri;
    std::array<bool, 2> turned;
};

/// Whether the surface at a boundary must show its normal turned round: a shape's own normal
/// points out of it, so at its enter it faces the line's origin and at its exit away; the
/// result's must face out of the result (into the origin's side where the line enters it).
inline bool csg_flip(bool at_exit, bool entering, bool turned) { return (at_exit == entering) != turned; }

/// The slot layout of object `o` of a scene.
inline CsgSlotLayout csg_slot_layout(const Scene& scene, const CsgObject& o) {
    CsgSlotLayout l;
    l.first_shape = o.first_shape;
    l.shapes = int(o.shape_count);
    int slot = 0;
    for (std::uint32_t s = 0; s < o.shape_count; ++s) {
        l.first_slot[s] = std::uint8_t(slot);
        const int n = csg_slots_of(scene.csg_shapes[o.first_shape + s].kind);
        for (int j = 0; j < n; ++j) l.shape_of[std::size_t(slot + j)] = std::uint8_t(s);
        slot += n;
    }
    l.first_slot[o.shape_count] = std::uint8_t(slot);
    return l;
}

}  // namespace streamrt
