#pragma once
// What one thread's whole-stream walk of a mesh holds (intersect_kernel.h's
// mesh_closest_streamed and mesh_stream_kernel.h's StreamWalker), for the memory check
// (driver/limits.cpp). A change to those buffers changes this bound.

namespace streamrt {

/// The most bytes the whole-stream walk holds on one thread for closest-hit streams of at most
/// `rays` rays over meshes whose trees are at most `tree_depth` levels of wide nodes deep
/// (accel::BuildStats::depth). Per ray: its number in the list of scattered rays (4 bytes), its
/// origin and direction in the mesh's space (24), 1 / direction (12), and the hit it had (a
/// triangle number and two barycentrics, 12); a flag per packet of 16 rays. The lists: a node
/// at level L (the root at 1) keeps its own list while it writes one list per child, each with
/// room for all of its own rays, so the walk down to level L holds at most
/// rays x (1 + 8 L) ray numbers (4 bytes each). Each buffer grows by half again when it must
/// grow (RawBuffer), hence the 1.5.
inline double mesh_stream_walk_bytes(double rays, int tree_depth) {
    constexpr double kPerRay = 4 + 24 + 12 + 12 + 1.0 / 16;
    constexpr double kGrowth = 1.5;
    return kGrowth * rays * (kPerRay + 4.0 * (1.0 + 8.0 * double(tree_depth)));
}

}  // namespace streamrt
