// The mesh's kernel layout beside the leaf-order triangles: each BVH leaf's triangles as
// structure-of-arrays blocks (MeshView::blocks), for the single-ray walk's leaf test.
#include <algorithm>
#include <limits>
#include <utility>

#include "mesh/mesh.h"
#include "parallel/parallelism.h"

namespace streamrt {

void Mesh::build_triangle_blocks() {
    // Leaves as (first triangle, count), in triangle order, so blocks follow the triangles.
    // The leaves cover the triangles in disjoint runs: their sizes marked at their first
    // triangles and read back in one pass put them in order without a sort.
    const std::size_t n = triangle_count();
    std::vector<std::uint32_t> size_at(n, 0);
    std::size_t n_leaves = 0;
    for (const accel::WideNode& nd : bvh.nodes)
        for (int j = 0; j < accel::kNodeWidth; ++j)
            if (nd.child[j] >= 0 && nd.count[j] > 0) {
                size_at[std::size_t(nd.child[j])] = nd.count[j];
                ++n_leaves;
            }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> leaves;
    leaves.reserve(n_leaves);
    for (std::size_t t = 0; t < n;)
        if (size_at[t] > 0) {
            leaves.emplace_back(std::uint32_t(t), size_at[t]);
            t += size_at[t];
        } else {
            ++t;  // not reached on a built mesh: every triangle is in a leaf
        }
    std::vector<std::uint32_t>().swap(size_at);
    std::vector<std::uint32_t> first_block(leaves.size() + 1, 0);
    for (std::size_t i = 0; i < leaves.size(); ++i)
        first_block[i + 1] = first_block[i] + (leaves[i].second + kBlockTriangles - 1) / kBlockTriangles;
    block_of.assign(n, 0);
    blocks.resize(first_block.back());  // every block is written in full below
    parallel_for_index(leaves.size(), 4096, [&](std::size_t i) {
        const auto [first, count] = leaves[i];
        block_of[first] = first_block[i];
        for (std::uint32_t k = 0; k < count; k += kBlockTriangles) {
            TriangleBlock& b = blocks[first_block[i] + k / kBlockTriangles];
            for (int lane = 0; lane < kBlockTriangles; ++lane) {
                const std::uint32_t t = first + k + std::uint32_t(lane);
                const bool real = k + std::uint32_t(lane) < count;
                for (int c = 0; c < 3; ++c)
                    for (int a = 0; a < 3; ++a)
                        b.corner[c][a][lane] = real ? corner(t, c)[a] : std::numeric_limits<float>::quiet_NaN();
            }
        }
    });
}

void Mesh::set_view(std::uint32_t single_ray_lanes) {
    kernel_view = {bvh.nodes.empty() ? nullptr : bvh.nodes.data(), positions.data(), index.data(), vertex_normals.data(),
                   std::uint32_t(triangle_count()), corner_uv.empty() ? nullptr : corner_uv.data(), uv_density,
                   blocks.data(), block_of.data(), single_ray_lanes,
                   positions.size() * sizeof(float) + index.size() * sizeof(std::uint32_t) +
                           bvh.nodes.size() * sizeof(accel::WideNode) >
                       kPrefetchedMeshBytes,
                   vertex_colors.empty() ? nullptr : vertex_colors.data()};
}

std::shared_ptr<const Mesh> Mesh::with_single_ray_lanes(std::uint32_t lanes) const {
    auto copy = std::make_shared<Mesh>(*this);
    copy->set_view(lanes);
    return copy;
}

}  // namespace streamrt
