#pragma once
// A mesh as a solid for constructive solid geometry (docs/scene-format.md, "CSG"): whether its
// triangles close a volume (checked when a csg block reads it), and the stretches of a line
// inside that volume (render/csg_spans.h).
#include <array>
#include <cstddef>
#include <optional>

#include "mesh/mesh.h"
#include "shapes/shapes.h"

namespace streamrt {

/// The first edge (in triangle order) that keeps a mesh from closing a volume: an edge between
/// two vertex positions (vertices at one position are one corner, so a seam of duplicated
/// vertices closes) must belong to exactly two triangles running along it in opposite
/// directions (consistently oriented). `triangles` counts the triangles on the edge;
/// `same_direction` is set when two of them run along it the same way (a flipped triangle).
struct OpenEdge {
    std::array<float, 3> a, b;  ///< the edge's ends, canonical space
    int triangles = 0;
    bool same_direction = false;
};
std::optional<OpenEdge> first_open_edge(const Mesh& mesh);

/// The most spans a mesh contributes to its csg object's span lists along one line: it counts
/// as this many shapes against kMaxCsgShapes (a convex shape is one span).
inline constexpr int kMeshCsgSpans = 8;
/// The most crossings of a line with one mesh that are kept, nearest first along the line.
inline constexpr int kMeshCsgCrossings = 64;

/// The slots a CSG shape of kind k takes (render/csg_layout.h): the spans a line may meet it
/// in, a closed mesh's first kMeshCsgSpans along the line, a canonical solid's 1 or its
/// kCsgSpans (the torus: 2).
constexpr int csg_slots_of(ShapeKind k) { return k == ShapeKind::Mesh ? kMeshCsgSpans : shape_csg_spans(k); }

}  // namespace streamrt
