#include "accel/bvh.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <type_traits>

#include <xsimd/xsimd.hpp>

#include "core/memory_advice.h"
#include "core/default_init.h"
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

/// Binary nodes of the SAH build; collapsed into WideNodes afterwards. Trivial on purpose:
/// room for the worst case (2n - 1 nodes) is reserved without being written, so only the
/// pages of nodes actually made count in memory (about half the worst case at 4 per leaf).
struct BinNode {
    float lo[3], hi[3];           ///< bounds (an Aabb's default values would make it non-trivial)
    std::int32_t left, right;     ///< inner: both >= 0; leaf: -1
    std::uint32_t first, count;  ///< leaf
    float half_area() const { return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}.half_area(); }
};
static_assert(std::is_trivially_default_constructible_v<BinNode>);

/// Binary depth past which the builder splits at the object median, so traversal stacks of a
/// fixed size always suffice (see bvh.h: 64 wide levels).
constexpr int kMedianDepth = 40;

/// A primitive as the builder moves it: its box and number, 32 bytes, partitioned in place so
/// that every pass over a node's primitives reads memory in order. Laid out so that lo and hi
/// each load as one 4-lane batch: lo's fourth lane is 0, hi's is the id (masked off).
struct Ref {
    float lo[3];
    float zero;  ///< always 0 (the SSE loads' fourth lane), written with the rest: no initialiser, so
                 ///< that an array of Refs is first touched by the loop that fills it (RefVec)
    float hi[3];
    std::uint32_t id;
    float c(int a) const { return lo[a] + hi[a]; }  ///< twice the centroid
    Aabb box() const { return Aabb{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
};
static_assert(sizeof(Ref) == 32);
static_assert(std::is_trivially_default_constructible_v<Ref>);
/// The builder's primitives: resize() leaves them unwritten (core/default_init.h).
using RefVec = FillLaterVec<Ref>;

/// 4-lane SSE2 batches (x, y, z, unused): the binning pass grows three boxes per primitive,
/// two instructions each this way instead of six.
using B4 = xsimd::batch<float, xsimd::sse2>;
using I4 = xsimd::batch<std::int32_t, xsimd::sse2>;

/// Trivially constructible, so a node's bin arrays cost nothing until reset (empty()).
struct Box4 {
    B4 lo, hi;
    static Box4 empty() {
        return {B4(std::numeric_limits<float>::infinity()), B4(-std::numeric_limits<float>::infinity())};
    }
    void grow(const B4& l, const B4& h) {
        lo = xsimd::min(lo, l);
        hi = xsimd::max(hi, h);
    }
    void grow(const Box4& b) { grow(b.lo, b.hi); }
    /// Aabb::half_area of a box that is not empty, without leaving the registers: the same
    /// products summed in the same order, so the same float.
    float half_area() const {
        const B4 e = hi - lo;                                                // x y z 0
        const B4 p = e * B4(_mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1)));  // xy yz zx 0
        alignas(16) float v[4];
        p.store_aligned(v);
        return v[0] + v[1] + v[2];
    }
    Aabb aabb() const {
        alignas(16) float l[4], h[4];
        lo.store_aligned(l);
        hi.store_aligned(h);
        return Aabb{{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    }
};

inline B4 ref_lo(const Ref& r) { return B4::load_unaligned(r.lo); }
inline B4 ref_hi(const Ref& r) {
    alignas(16) static constexpr std::int32_t kXyz[4] = {-1, -1, -1, 0};
    return B4::load_unaligned(r.hi) & xsimd::bitwise_cast<B4>(I4::load_aligned(kXyz));  // the id's bits out
}

struct Builder {
    RefVec& refs;
    std::unique_ptr<BinNode[]> nodes;
    std::atomic<std::uint32_t> n_nodes{0};
    BuildOptions opt;


    std::uint32_t alloc() { return n_nodes.fetch_add(1, std::memory_order_relaxed); }

    /// The bin of each axis for a doubled centroid c: trunc((c - lo) * scale) clamped to
    /// [0, last]. One rule for binning and partitioning, so both agree on every primitive.
    struct BinOf {
        B4 lo, scale;
        float last;
        I4 operator()(const B4& c) const {
            return xsimd::to_int(xsimd::min(xsimd::max((c - lo) * scale, B4(0.f)), B4(last)));
        }
    };

    static constexpr int kMaxBins = 64;

    /// Per axis and bin: the primitives' boxes and their count. Consecutive primitives of a
    /// mesh mostly fall in the same bins, so growing one set of bins makes each step wait
    /// for the last one's store; large nodes take two sets by turns, merged at the end.
    /// (The children's centroid bounds come from the partition pass.)
    struct Bins {
        static constexpr std::uint32_t kTwoSets = 256;  // below, a second set costs about what it saves
        Box4 box[3][kMaxBins];
        std::uint32_t count[3][kMaxBins];

        void fill(const Ref* r, std::uint32_t n, int nb, const BinOf& bin_of) {
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < nb; ++b) {
                    box[a][b] = Box4::empty();
                    count[a][b] = 0;
                }
            const auto add = [&](Box4 (&to)[3][kMaxBins], std::uint32_t (&to_count)[3][kMaxBins], const Ref& x) {
                const B4 lo = ref_lo(x), hi = ref_hi(x);
                alignas(16) std::int32_t b[4];
                bin_of(lo + hi).store_aligned(b);
                for (int a = 0; a < 3; ++a) {
                    to[a][b[a]].grow(lo, hi);
                    ++to_count[a][b[a]];
                }
            };
            if (n < kTwoSets) {
                for (std::uint32_t k = 0; k < n; ++k) add(box, count, r[k]);
                return;
            }
            Box4 other[3][kMaxBins];
            std::uint32_t other_count[3][kMaxBins];
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < nb; ++b) {
                    other[a][b] = Box4::empty();
                    other_count[a][b] = 0;
                }
            std::uint32_t k = 0;
            for (; k + 1 < n; k += 2) {
                add(box, count, r[k]);
                add(other, other_count, r[k + 1]);
            }
            if (k < n) add(box, count, r[k]);
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < nb; ++b) {
                    box[a][b].grow(other[a][b]);
                    count[a][b] += other_count[a][b];
                }
        }
    };

    /// Moves refs[first, first + count) whose bin on `axis` is at most `last_left` before the
    /// others, and returns where the others start; csides get the doubled-centroid bounds of
    /// each side. The order is std::partition's (libstdc++, bidirectional: swap the first
    /// from the left that goes right with the first from the right that goes left), so the
    /// tree is the one the builder made when its centroid bounds came from extra bins.
    std::uint32_t partition(std::uint32_t first, std::uint32_t count, const BinOf& bin_of, int axis, int last_left,
                            Box4 csides[2]) {
        csides[0] = csides[1] = Box4::empty();
        Ref* lo_it = refs.data() + first;
        Ref* hi_it = lo_it + count;
        const auto centre = [](const Ref& x) { return ref_lo(x) + ref_hi(x); };
        const auto goes_left = [&](const B4& c) {
            alignas(16) std::int32_t b[4];
            bin_of(c).store_aligned(b);
            return b[axis] <= last_left;
        };
        for (;;) {
            B4 c_right;  // the centroid of *lo_it once it stops: the first from the left that goes right
            for (;; ++lo_it) {
                if (lo_it == hi_it) return std::uint32_t(lo_it - refs.data());
                c_right = centre(*lo_it);
                if (!goes_left(c_right)) break;
                csides[0].grow(c_right, c_right);
            }
            csides[1].grow(c_right, c_right);
            B4 c_left;
            for (;;) {
                --hi_it;
                if (lo_it == hi_it) return std::uint32_t(lo_it - refs.data());
                c_left = centre(*hi_it);
                if (goes_left(c_left)) break;
                csides[1].grow(c_left, c_left);
            }
            csides[0].grow(c_left, c_left);
            std::swap(*lo_it, *hi_it);
            ++lo_it;
        }
    }

    /// Bounds and doubled-centroid bounds of refs[begin, end).
    void bounds_of(std::uint32_t begin, std::uint32_t end, Aabb& box, Aabb& cbox) const {
        Box4 b = Box4::empty(), c = Box4::empty();
        for (std::uint32_t k = begin; k < end; ++k) {
            const B4 lo = ref_lo(refs[k]), hi = ref_hi(refs[k]), cen = lo + hi;
            b.grow(lo, hi);
            c.grow(cen, cen);
        }
        box = b.aabb();
        cbox = c.aabb();
    }

    void make_leaf(std::uint32_t node, std::uint32_t first, std::uint32_t count) {
        nodes[node].left = nodes[node].right = -1;
        nodes[node].first = first;
        nodes[node].count = count;
    }

    /// Builds node `node` over idx[first, first + count) whose bounds are `box`.
    /// cbox: the bounds of the primitives' doubled centroids (Ref::c).
    void build(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Aabb& box, const Aabb& cbox,
               int depth) {
        std::copy_n(box.lo, 3, nodes[node].lo);
        std::copy_n(box.hi, 3, nodes[node].hi);
        if (count <= 1) return make_leaf(node, first, count);
        std::uint32_t mid = first;
        bool split = false;
        Aabb lb, rb, lc, rc;  // the children's bounds and centroid bounds
        if (depth < kMedianDepth) {
            // Binned SAH over the three axes, one pass over the primitives; small nodes use
            // fewer bins (as many as primitives), so the bottom of the tree stays cheap.
            const int nb = std::clamp(std::min(opt.bins, int(count)), 2, kMaxBins);
            alignas(16) float scale[4] = {0.f, 0.f, 0.f, 0.f};
            for (int a = 0; a < 3; ++a) {
                const float ext = cbox.hi[a] - cbox.lo[a];
                scale[a] = ext > 0.f ? float(nb) / ext * 0.99999f : 0.f;
            }
            alignas(16) const float origin[4] = {cbox.lo[0], cbox.lo[1], cbox.lo[2], 0.f};
            const BinOf bin_of{B4::load_aligned(origin), B4::load_aligned(scale), float(nb - 1)};
            Bins bins;
            bins.fill(refs.data() + first, count, nb, bin_of);
            float best_cost = std::numeric_limits<float>::infinity();
            int best_axis = -1, best_bin = 0;
            for (int a = 0; a < 3; ++a) {
                if (!(scale[a] > 0.f)) continue;
                float right_area[kMaxBins];
                std::uint32_t right_count[kMaxBins];
                Box4 acc = Box4::empty();
                std::uint32_t cnt = 0;
                for (int b = nb - 1; b > 0; --b) {
                    acc.grow(bins.box[a][b]);
                    cnt += bins.count[a][b];
                    right_area[b] = cnt ? acc.half_area() : 0.f;
                    right_count[b] = cnt;
                }
                acc = Box4::empty();
                cnt = 0;
                for (int b = 0; b < nb - 1; ++b) {
                    acc.grow(bins.box[a][b]);
                    cnt += bins.count[a][b];
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
                // The same bin rule as the binning pass, so the sides are exactly the bins'.
                Box4 csides[2];
                mid = partition(first, count, bin_of, best_axis, best_bin, csides);
                split = mid > first && mid < first + count;
                // The children's bounds are the unions of their bins (the partition used the
                // same bin rule), exactly what a pass over their primitives would give.
                Box4 sides[2] = {Box4::empty(), Box4::empty()};
                for (int b = 0; b < nb; ++b) sides[b > best_bin].grow(bins.box[best_axis][b]);
                lb = sides[0].aabb(), rb = sides[1].aabb(), lc = csides[0].aabb(), rc = csides[1].aabb();
            }
        }
        if (!split) {
            if (count <= std::uint32_t(opt.max_leaf)) return make_leaf(node, first, count);
            lb = rb = lc = rc = Aabb{};
            // Object median along the widest centroid axis (all centroids equal: any halves).
            int a = 0;
            for (int k = 1; k < 3; ++k)
                if (cbox.hi[k] - cbox.lo[k] > cbox.hi[a] - cbox.lo[a]) a = k;
            mid = first + count / 2;
            std::nth_element(refs.begin() + first, refs.begin() + mid, refs.begin() + first + count,
                             [&](const Ref& x, const Ref& y) { return x.c(a) < y.c(a); });
            bounds_of(first, mid, lb, lc);
            bounds_of(mid, first + count, rb, rc);
        }
        const std::uint32_t l = alloc(), r = alloc();
        nodes[node].first = nodes[node].count = 0;
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

/// Collapses the binary tree into 8-wide nodes with the least SAH cost, by dynamic
/// programming over the binary tree (after Ylitie, Karras and Laine 2017, "Efficient
/// incoherent ray traversal on GPUs through compressed wide BVHs"). A greedy collapse (open
/// the largest child until a node has 8) left two thirds of a large mesh's nodes with two
/// children: every subtree its parent had no room for became a node of its own. The leaves
/// are the binary tree's whatever the collapse, so the cost that changes is the wide nodes':
/// a node of k children costs its area (the chance that a ray visits it) times
/// (1 + child_cost k), child_cost being one child box test relative to the rest of a visit
/// (BuildOptions::wide_child_cost). exact[b][k - 1] is the least cost of covering binary node
/// b's subtree with exactly k children of one wide node (a child is a leaf, or a wide node
/// of its own; infinite when the subtree has fewer than k leaves).
struct Collapser {
    const BinNode* bin;
    simd::AlignedVec<WideNode>& out;
    float child_cost;
    std::unique_ptr<std::array<float, kNodeWidth>[]> exact;
    std::size_t leaves = 0;
    int depth = 0;  ///< the deepest level emitted (the root's: 1)

    static constexpr float kInf = std::numeric_limits<float>::infinity();

    /// The least exact[left][j - 1] + exact[right][k - j - 1] over j, and that j.
    std::pair<float, int> split(const BinNode& n, int k) const {
        const auto& l = exact[std::size_t(n.left)];
        const auto& r = exact[std::size_t(n.right)];
        float c = kInf;
        int arg = 1;
        for (int j = 1; j < k; ++j) {
            const float cj = l[std::size_t(j - 1)] + r[std::size_t(k - j - 1)];
            if (cj < c) c = cj, arg = j;
        }
        return {c, arg};
    }
    /// The number of children, from 2 to 8, of the cheapest wide node at inner node b.
    int node_children(std::int32_t b) const {
        const BinNode& n = bin[std::size_t(b)];
        float c = kInf;
        int arg = 2;
        for (int k = 2; k <= kNodeWidth; ++k) {
            const float ck = n.half_area() * (1.f + child_cost * float(k)) + exact[std::size_t(b)][std::size_t(k - 1)];
            if (ck < c) c = ck, arg = k;
        }
        return arg;
    }

    /// Fills exact[] over b's subtree (children first; the halves of the top levels in parallel).
    void solve(std::int32_t b, int depth) {
        const BinNode& n = bin[std::size_t(b)];
        auto& c = exact[std::size_t(b)];
        if (n.left < 0) {
            c.fill(kInf);
            c[0] = 0.f;
            return;
        }
        if (depth < 10) {
            parallel_invoke([&] { solve(n.left, depth + 1); }, [&] { solve(n.right, depth + 1); });
        } else {
            solve(n.left, depth + 1);
            solve(n.right, depth + 1);
        }
        for (int k = 2; k <= kNodeWidth; ++k) c[std::size_t(k - 1)] = split(n, k).first;
        const int k = node_children(b);  // b as a wide node of its own
        c[0] = n.half_area() * (1.f + child_cost * float(k)) + c[std::size_t(k - 1)];
    }

    /// The k children that cover b's subtree at exact[b][k - 1].
    void cut(std::int32_t b, int k, std::int32_t* kids, int& nk) const {
        const BinNode& n = bin[std::size_t(b)];
        if (k == 1 || n.left < 0) {  // (a leaf has a finite cost for k = 1 only)
            kids[nk++] = b;
            return;
        }
        const int j = split(n, k).second;
        cut(n.left, j, kids, nk);
        cut(n.right, k - j, kids, nk);
    }

    /// Emits the wide node of binary node b, at `level` (the root's: 1), then its inner
    /// children's nodes (parents first, which refit relies on); returns its index.
    std::int32_t emit(std::int32_t b, int level) {
        depth = std::max(depth, level);
        const std::size_t me = out.size();
        out.emplace_back();
        std::int32_t kids[kNodeWidth];
        int nk = 0;
        const BinNode& root = bin[std::size_t(b)];
        if (root.left < 0) {
            kids[nk++] = b;  // a leaf at the root: one child
        } else {
            cut(b, node_children(b), kids, nk);
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
            n.lo_x[j] = c.lo[0];
            n.lo_y[j] = c.lo[1];
            n.lo_z[j] = c.lo[2];
            n.hi_x[j] = c.hi[0];
            n.hi_y[j] = c.hi[1];
            n.hi_z[j] = c.hi[2];
            if (c.left < 0) {
                n.child[j] = std::int32_t(c.first);
                n.count[j] = c.count;
                ++leaves;
            }
        }
        out[me] = n;
        for (int j = 0; j < nk; ++j) {
            if (bin[std::size_t(kids[j])].left < 0) continue;
            const std::int32_t child = emit(kids[j], level + 1);
            out[me].child[j] = child;
            out[me].count[j] = 0;
        }
        return std::int32_t(me);
    }
};

/// The hierarchy over refs (the primitives with non-empty boxes, in their numbers' order).
Bvh build_over(RefVec refs, const BuildOptions& options, std::chrono::steady_clock::time_point start);

}  // namespace

Bvh Bvh::build(std::vector<Aabb> boxes, const BuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    RefVec refs;
    refs.reserve(boxes.size());
    want_huge_pages(refs.data(), refs.capacity());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        const Aabb& b = boxes[i];
        if (!b.empty()) refs.push_back({{b.lo[0], b.lo[1], b.lo[2]}, 0.f, {b.hi[0], b.hi[1], b.hi[2]}, std::uint32_t(i)});
    }
    std::vector<Aabb>().swap(boxes);  // the refs hold them now: free the memory before building
    return build_over(std::move(refs), options, start);
}

Bvh Bvh::build(std::size_t n, const std::function<Aabb(std::size_t)>& box_of, const BuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    // Every Ref is written below, in parallel: their pages are first touched (and zeroed by the
    // kernel) there, by both threads, not by a memset on this one.
    RefVec refs(n);
    want_huge_pages(refs.data(), refs.capacity());
    std::atomic<bool> any_empty{false};
    parallel_for_index(n, 16384, [&](std::size_t i) {
        const Aabb b = box_of(i);
        refs[i] = {{b.lo[0], b.lo[1], b.lo[2]}, 0.f, {b.hi[0], b.hi[1], b.hi[2]}, std::uint32_t(i)};
        if (b.empty()) any_empty.store(true, std::memory_order_relaxed);
    });
    if (any_empty.load())  // rare: keep the others, in order, as the vector form does
        std::erase_if(refs, [](const Ref& r) { return r.box().empty(); });
    return build_over(std::move(refs), options, start);
}

namespace {

Bvh build_over(RefVec refs, const BuildOptions& options, std::chrono::steady_clock::time_point start) {
    Bvh bvh;
    if (refs.empty()) return bvh;
    const std::size_t n = refs.size();

    // Worst case 2n - 1 nodes, left unwritten (see BinNode).
    Builder b{refs, std::make_unique_for_overwrite<BinNode[]>(2 * n), {}, options};
    want_huge_pages(b.nodes.get(), 2 * n);
    Aabb all, call;
    b.bounds_of(0, std::uint32_t(n), all, call);
    const std::uint32_t root = b.alloc();
    b.build(root, 0, std::uint32_t(n), all, call, 0);
    const std::size_t n_binary = b.n_nodes.load();

    Collapser c{b.nodes.get(), bvh.nodes, options.wide_child_cost,
                std::make_unique_for_overwrite<std::array<float, kNodeWidth>[]>(n_binary)};
    c.solve(0, 0);
    bvh.nodes.reserve(n_binary / 6 + 1);
    c.emit(0, 1);
    bvh.prim_index.resize(n);
    parallel_for_index(n, 65536, [&](std::size_t k) { bvh.prim_index[k] = refs[k].id; });
    bvh.bounds = all;
    bvh.stats.binary_nodes = n_binary;
    bvh.stats.wide_nodes = bvh.nodes.size();
    bvh.stats.leaves = c.leaves;
    bvh.stats.depth = c.depth;
    bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace

BvhLinks::BvhLinks(const Bvh& bvh, std::size_t prims)
    : parent(bvh.nodes.size(), -1), slot(bvh.nodes.size(), 0), leaf_node(prims, -1), leaf_slot(prims, 0) {
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        const WideNode& n = bvh.nodes[i];
        for (int j = 0; j < kNodeWidth; ++j) {
            if (n.child[j] < 0) continue;
            if (n.count[j] == 0) {
                parent[std::size_t(n.child[j])] = std::int32_t(i);
                slot[std::size_t(n.child[j])] = std::uint8_t(j);
            } else {
                for (std::uint32_t k = 0; k < n.count[j]; ++k) {
                    leaf_node[std::size_t(n.child[j]) + k] = std::int32_t(i);
                    leaf_slot[std::size_t(n.child[j]) + k] = std::uint8_t(j);
                }
            }
        }
    }
}

namespace {
void set_child_box(WideNode& n, int j, const Aabb& b) {
    n.lo_x[j] = b.lo[0], n.lo_y[j] = b.lo[1], n.lo_z[j] = b.lo[2];
    n.hi_x[j] = b.hi[0], n.hi_y[j] = b.hi[1], n.hi_z[j] = b.hi[2];
}
Aabb node_box(const WideNode& n) {
    Aabb b;
    for (int j = 0; j < kNodeWidth; ++j) {
        if (n.child[j] < 0) continue;
        Aabb c;
        c.lo[0] = n.lo_x[j], c.lo[1] = n.lo_y[j], c.lo[2] = n.lo_z[j];
        c.hi[0] = n.hi_x[j], c.hi[1] = n.hi_y[j], c.hi[2] = n.hi_z[j];
        b.grow(c);
    }
    return b;
}
}  // namespace

void refit(Bvh& bvh, const BvhLinks& links, std::span<const std::uint32_t> moved,
           const std::function<Aabb(std::uint32_t)>& box) {
    if (bvh.empty() || moved.empty()) return;
    // Nodes are emitted parents first (Collapser::emit), so a descending sweep over the dirty
    // nodes visits every child before its parent.
    std::vector<std::uint8_t> dirty(bvh.nodes.size(), 0);
    std::size_t top = 0;
    for (const std::uint32_t pos : moved) {
        const std::int32_t node = links.leaf_node[pos];
        const int j = links.leaf_slot[pos];
        WideNode& n = bvh.nodes[std::size_t(node)];
        Aabb leaf;
        for (std::uint32_t k = 0; k < n.count[j]; ++k) leaf.grow(box(std::uint32_t(n.child[j]) + k));
        set_child_box(n, j, leaf);
        dirty[std::size_t(node)] = 1;
        top = std::max(top, std::size_t(node));
    }
    for (std::size_t i = top + 1; i-- > 0;) {
        if (!dirty[i]) continue;
        const std::int32_t p = links.parent[i];
        if (p < 0) continue;
        set_child_box(bvh.nodes[std::size_t(p)], links.slot[i], node_box(bvh.nodes[i]));
        dirty[std::size_t(p)] = 1;
    }
    bvh.bounds = node_box(bvh.nodes[0]);
}

}  // namespace streamrt::accel
