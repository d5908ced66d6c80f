// Closedness of a mesh for CSG (mesh/mesh_solid.h).
#include "mesh/mesh_solid.h"

#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>

namespace streamrt {

namespace {
struct PositionKey {
    std::uint32_t bits[3];
    bool operator==(const PositionKey& o) const { return std::memcmp(bits, o.bits, sizeof bits) == 0; }
};
struct PositionHash {
    std::size_t operator()(const PositionKey& k) const {
        std::uint64_t h = 1469598103934665603ull;
        for (const std::uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
        return std::size_t(h);
    }
};
/// Triangles along an edge {lo, hi} (corner numbers, lo < hi): from lo to hi, and back.
struct EdgeUse {
    int forward = 0, backward = 0;
};
}  // namespace

std::optional<OpenEdge> first_open_edge(const Mesh& mesh) {
    const std::size_t n_vertices = mesh.positions.size() / 3;
    // Corners: vertices at bit-identical positions are one (0.0 and -0.0 apart: the watertight
    // triangle test, which makes a closed surface count each line's crossing once, sees them
    // as one point too, but no mesh writer emits both).
    std::vector<std::uint32_t> corner(n_vertices);
    std::unordered_map<PositionKey, std::uint32_t, PositionHash> at;
    at.reserve(n_vertices);
    for (std::size_t v = 0; v < n_vertices; ++v) {
        PositionKey k;
        std::memcpy(k.bits, &mesh.positions[3 * v], sizeof k.bits);
        corner[v] = at.try_emplace(k, std::uint32_t(at.size())).first->second;
    }
    const auto edge_key = [](std::uint32_t a, std::uint32_t b) {
        return a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
    };
    std::unordered_map<std::uint64_t, EdgeUse> edges;
    edges.reserve(3 * mesh.triangle_count() / 2 + 1);
    const std::size_t n = mesh.triangle_count();
    for (std::size_t k = 0; k < n; ++k)
        for (int j = 0; j < 3; ++j) {
            const std::uint32_t a = corner[mesh.index[3 * k + std::size_t(j)]];
            const std::uint32_t b = corner[mesh.index[3 * k + std::size_t((j + 1) % 3)]];
            EdgeUse& e = edges[edge_key(a, b)];
            (a < b ? e.forward : e.backward) += 1;
        }
    // The first bad edge in triangle order, so the message does not depend on hash order.
    for (std::size_t k = 0; k < n; ++k)
        for (int j = 0; j < 3; ++j) {
            const std::uint32_t va = mesh.index[3 * k + std::size_t(j)], vb = mesh.index[3 * k + std::size_t((j + 1) % 3)];
            const EdgeUse& e = edges[edge_key(corner[va], corner[vb])];
            if (e.forward == 1 && e.backward == 1) continue;
            OpenEdge o;
            for (int c = 0; c < 3; ++c) {
                o.a[std::size_t(c)] = mesh.positions[3 * std::size_t(va) + std::size_t(c)];
                o.b[std::size_t(c)] = mesh.positions[3 * std::size_t(vb) + std::size_t(c)];
            }
            o.triangles = e.forward + e.backward;
            o.same_direction = e.forward > 1 || e.backward > 1;
            return o;
        }
    return std::nullopt;
}

}  // namespace streamrt
