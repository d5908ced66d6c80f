#include "accel/bvh.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "parallel/parallelism.h"

namespace streamrt::accel {

Aabb conservative_box(const double lo[3], const double hi[3]) {
    Aabb b;
    for (int a = 0; a < 3; ++a) {
        const double pad = 1e-6 * (hi[a] - lo[a]) + 1e-7 * std::max(std::abs(lo[a]), std::abs(hi[a])) + 1e-30;
        b.lo[a] = std::nextafter(float(lo[a] - pad), -std::numeric_limits<float>::infinity());
        b.hi[a] = std::nextafter(float(hi[a] + pad), std::numeric_limits<float>::infinity());
    }
    return b;
}

namespace {

/// Binary nodes of the SAH build; collapsed into WideNodes afterwards.
struct BinNode {
    Aabb box;
    std::int32_t left = -1, right = -1;  ///< inner: both >= 0
    std::uint32_t first = 0, count = 0;  ///< leaf
};

/// Binary depth past which the builder splits at the object median, so traversal stacks of a
/// fixed size always suffice (see bvh.h: 64 wide levels).
constexpr int kMedianDepth = 40;

/// A primitive as the builder moves it: its box and number, 32 bytes, partitioned in place so
/// that every pass over a node's primitives reads memory in order.
struct Ref {
    Aabb box;
    std::uint32_t id;
    float pad;
    float c(int a) const { return box.lo[a] + box.hi[a]; }  ///< twice the centroid
};

struct Builder {
    std::vector<Ref>& refs;
    std::vector<BinNode> nodes;
    std::atomic<std::uint32_t> n_nodes{0};
    BuildOptions opt;


    std::uint32_t alloc() { return n_nodes.fetch_add(1, std::memory_order_relaxed); }

    void make_leaf(std::uint32_t node, std::uint32_t first, std::uint32_t count) {
        nodes[node].first = first;
        nodes[node].count = count;
    }

    /// Builds node `node` over idx[first, first + count) whose bounds are `box`.
    /// cbox: the bounds of the primitives' doubled centroids (Ref::c).
    void build(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Aabb& box, const Aabb& cbox,
               int depth) {
        nodes[node].box = box;
        if (count <= 1) return make_leaf(node, first, count);
        std::uint32_t mid = first;
        bool split = false;
        if (depth < kMedianDepth) {
            // Binned SAH over the three axes, one pass over the primitives; small nodes use
            // fewer bins (as many as primitives), so the bottom of the tree stays cheap.
            constexpr int kMaxBins = 64;
            const int nb = std::clamp(std::min(opt.bins, int(count)), 2, kMaxBins);
            float best_cost = std::numeric_limits<float>::infinity();
            int best_axis = -1, best_bin = 0;
            Aabb bb[3][kMaxBins];
            std::uint32_t bc[3][kMaxBins];
            float scale[3];
            for (int a = 0; a < 3; ++a) {
                const float ext = cbox.hi[a] - cbox.lo[a];
                scale[a] = ext > 0.f ? float(nb) / ext * 0.99999f : 0.f;
                for (int b = 0; b < nb; ++b) {
                    bb[a][b] = Aabb{};
                    bc[a][b] = 0;
                }
            }
            for (std::uint32_t k = first; k < first + count; ++k) {
                const Aabb& box_i = refs[k].box;
                const float c[3] = {refs[k].c(0), refs[k].c(1), refs[k].c(2)};
                for (int a = 0; a < 3; ++a) {
                    const int b = std::clamp(int((c[a] - cbox.lo[a]) * scale[a]), 0, nb - 1);
                    bb[a][b].grow(box_i);
                    ++bc[a][b];
                }
            }
            for (int a = 0; a < 3; ++a) {
                if (!(scale[a] > 0.f)) continue;
                float right_area[kMaxBins];
                std::uint32_t right_count[kMaxBins];
                Aabb acc;
                std::uint32_t cnt = 0;
                for (int b = nb - 1; b > 0; --b) {
                    acc.grow(bb[a][b]);
                    cnt += bc[a][b];
                    right_area[b] = acc.half_area();
                    right_count[b] = cnt;
                }
                acc = Aabb{};
                cnt = 0;
                for (int b = 0; b < nb - 1; ++b) {
                    acc.grow(bb[a][b]);
                    cnt += bc[a][b];
                    if (cnt == 0 || right_count[b + 1] == 0) continue;
                    const float cost = acc.half_area() * float(cnt) + right_area[b + 1] * float(right_count[b + 1]);
                    if (cost < best_cost) {
                        best_cost = cost;
                        best_axis = a;
                        best_bin = b;
                    }
                }
            }
            if (best_axis >= 0) {
                const float leaf_cost = box.half_area() * float(count);
                const float split_cost = opt.traversal_cost * box.half_area() + best_cost;
                if (count <= std::uint32_t(opt.max_leaf) && leaf_cost <= split_cost)
                    return make_leaf(node, first, count);
                const int a = best_axis;
                const float sc = scale[a];
                const auto it = std::partition(refs.begin() + first, refs.begin() + first + count, [&](const Ref& r) {
                    return std::clamp(int((r.c(a) - cbox.lo[a]) * sc), 0, nb - 1) <= best_bin;
                });
                mid = std::uint32_t(it - refs.begin());
                split = mid > first && mid < first + count;
            }
        }
        if (!split) {
            if (count <= std::uint32_t(opt.max_leaf)) return make_leaf(node, first, count);
            // Object median along the widest centroid axis (all centroids equal: any halves).
            int a = 0;
            for (int k = 1; k < 3; ++k)
                if (cbox.hi[k] - cbox.lo[k] > cbox.hi[a] - cbox.lo[a]) a = k;
            mid = first + count / 2;
            std::nth_element(refs.begin() + first, refs.begin() + mid, refs.begin() + first + count,
                             [&](const Ref& x, const Ref& y) { return x.c(a) < y.c(a); });
        }
        Aabb lb, rb, lc, rc;
        for (std::uint32_t k = first; k < mid; ++k) {
            lb.grow(refs[k].box);
            const float c[3] = {refs[k].c(0), refs[k].c(1), refs[k].c(2)};
            lc.grow(c);
        }
        for (std::uint32_t k = mid; k < first + count; ++k) {
            rb.grow(refs[k].box);
            const float c[3] = {refs[k].c(0), refs[k].c(1), refs[k].c(2)};
            rc.grow(c);
        }
        const std::uint32_t l = alloc(), r = alloc();
        nodes[node].left = std::int32_t(l);
        nodes[node].right = std::int32_t(r);
        const std::uint32_t nl = mid - first, nr = first + count - mid;
        if (count >= opt.parallel_grain) {
            parallel_invoke([&] { build(l, first, nl, lb, lc, depth + 1); },
                            [&] { build(r, mid, nr, rb, rc, depth + 1); });
        } else {
            build(l, first, nl, lb, lc, depth + 1);
            build(r, mid, nr, rb, rc, depth + 1);
        }
    }
};

/// Collapses the binary tree into 8-wide nodes: a wide node takes its binary node's two
/// children, then repeatedly opens the inner child of largest area until it has 8.
struct Collapser {
    const std::vector<BinNode>& bin;
    simd::AlignedVec<WideNode>& out;
    std::size_t leaves = 0;

    std::int32_t emit(std::int32_t b) {
        const std::size_t me = out.size();
        out.emplace_back();
        std::int32_t kids[kNodeWidth];
        int nk = 0;
        const BinNode& root = bin[std::size_t(b)];
        if (root.left < 0) {
            kids[nk++] = b;  // a leaf at the root: one child
        } else {
            kids[nk++] = root.left;
            kids[nk++] = root.right;
            while (nk < kNodeWidth) {
                int best = -1;
                float best_area = -1.f;
                for (int k = 0; k < nk; ++k) {
                    const BinNode& c = bin[std::size_t(kids[k])];
                    if (c.left >= 0 && c.box.half_area() > best_area) {
                        best_area = c.box.half_area();
                        best = k;
                    }
                }
                if (best < 0) break;
                const BinNode& c = bin[std::size_t(kids[best])];
                kids[best] = c.left;
                kids[nk++] = c.right;
            }
        }
        WideNode n;
        for (int j = 0; j < kNodeWidth; ++j) {
            n.lo_x[j] = n.lo_y[j] = n.lo_z[j] = std::numeric_limits<float>::infinity();
            n.hi_x[j] = n.hi_y[j] = n.hi_z[j] = -std::numeric_limits<float>::infinity();
            n.child[j] = -1;
            n.count[j] = 0;
        }
        for (int j = 0; j < nk; ++j) {
            const BinNode& c = bin[std::size_t(kids[j])];
            n.lo_x[j] = c.box.lo[0];
            n.lo_y[j] = c.box.lo[1];
            n.lo_z[j] = c.box.lo[2];
            n.hi_x[j] = c.box.hi[0];
            n.hi_y[j] = c.box.hi[1];
            n.hi_z[j] = c.box.hi[2];
            if (c.left < 0) {
                n.child[j] = std::int32_t(c.first);
                n.count[j] = c.count;
                ++leaves;
            }
        }
        out[me] = n;
        for (int j = 0; j < nk; ++j) {
            const BinNode& c = bin[std::size_t(kids[j])];
            if (c.left >= 0) {
                const std::int32_t child = emit(kids[j]);
                out[me].child[j] = child;
                out[me].count[j] = 0;
            }
        }
        return std::int32_t(me);
    }
};

}  // namespace

Bvh Bvh::build(const std::vector<Aabb>& boxes, const BuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    Bvh bvh;
    std::vector<Ref> refs;
    refs.reserve(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
        if (!boxes[i].empty()) refs.push_back({boxes[i], std::uint32_t(i), 0.f});
    if (refs.empty()) return bvh;
    const std::size_t n = refs.size();

    Builder b{refs, {}, {}, options};
    Aabb all, call;
    for (const Ref& r : refs) {
        all.grow(r.box);
        const float c[3] = {r.c(0), r.c(1), r.c(2)};
        call.grow(c);
    }
    b.nodes.resize(2 * n);
    const std::uint32_t root = b.alloc();
    b.build(root, 0, std::uint32_t(n), all, call, 0);
    b.nodes.resize(b.n_nodes.load());

    Collapser c{b.nodes, bvh.nodes};
    bvh.nodes.reserve(b.nodes.size() / 4 + 1);
    c.emit(0);
    bvh.prim_index.resize(n);
    parallel_for_index(n, 65536, [&](std::size_t k) { bvh.prim_index[k] = refs[k].id; });
    bvh.bounds = all;
    bvh.stats.binary_nodes = b.nodes.size();
    bvh.stats.wide_nodes = bvh.nodes.size();
    bvh.stats.leaves = c.leaves;
    bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace streamrt::accel
