#include "driver/adaptive_render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>

#include "core/default_init.h"

namespace streamrt {

namespace {

/// The side of the pixel blocks whose corners the corner round traces together (2 x 2 tiles).
constexpr int kCornerBlock = 2 * kTileSize;

/// The stride of an interleaved order of n items (item k * stride mod n at step k): near n
/// over the golden ratio, and prime to n so that every item comes once. Neighbours in the
/// image are then far apart in the order (why: render_adaptive_image's tile order).
std::size_t interleave_stride(std::size_t n) {
    std::size_t stride = std::max<std::size_t>(1, std::size_t(double(n) * 0.618));
    while (std::gcd(stride, n) != 1) ++stride;
    return stride;
}

/// A tally for every pixel of `tile` (no corner round, or a tile rendered alone).
TileTallies dense_tallies(const Tile& tile) {
    const std::size_t n = std::size_t(tile.width()) * std::size_t(tile.height());
    TileTallies t{tile, std::vector<PixelTally>(n), std::vector<std::uint32_t>(n), std::vector<std::uint8_t>(n, 0), {}};
    std::iota(t.pixel.begin(), t.pixel.end(), 0u);
    return t;
}

/// The tally of a pixel's corner round: its four corners at `c`, `c` + 1, `c` + `row` and
/// `c` + `row` + 1 of a corner rectangle's colours (3 floats each), in a fixed order (top left,
/// top right, bottom left, bottom right).
PixelTally corner_tally(const float* rgb, std::size_t row, std::size_t c) {
    PixelTally p;
    for (const std::size_t k : {c, c + 1, c + row, c + row + 1}) p.add_corner(rgb[k * 3], rgb[k * 3 + 1], rgb[k * 3 + 2]);
    return p;
}

/// Runs round r on the tallies of `t` that take it; returns how many did. `counts` gets the
/// rays traced.
int refine(PreparedRender& prepared, int r, TileTallies& t, RayCounts& counts, const RenderProgress* cancel) {
    const SampleRun run = adaptive_round(r, prepared.adaptive.cap);
    // Per-thread scratch: the tallies taking the round, their pixels and their samples' colours.
    static thread_local std::vector<std::uint32_t> chosen, pixels;
    static thread_local std::vector<float> colours;
    chosen.clear();
    pixels.clear();
    const auto consider = [&](std::uint32_t i) {
        if (prepared.adaptive.takes_round(t.tallies[i], r, run, t.spread_near[i] != 0)) {
            chosen.push_back(i);
            pixels.push_back(t.pixel[i]);
        }
    };
    // From round 2 on only the tallies that took the last round may take this one.
    if (r >= 2) {
        for (const std::uint32_t i : t.took_last) consider(i);
    } else {
        for (std::size_t i = 0; i < t.tallies.size(); ++i) consider(std::uint32_t(i));
    }
    t.took_last.assign(chosen.begin(), chosen.end());
    if (pixels.empty()) return 0;
    colours.resize(pixels.size() * std::size_t(run.count) * 3);
    prepared.render_samples(t.tile, run, pixels.data(), int(pixels.size()), colours.data(), counts, cancel);
    if (cancel && cancel->cancelled()) return 0;
    // The samples go into each tally in their order: the same sums whatever else was traced.
    const float* c = colours.data();
    for (const std::uint32_t i : chosen) {
        t.tallies[i].begin_round();
        for (int j = 0; j < run.count; ++j, c += 3) t.tallies[i].add(c[0], c[1], c[2]);
    }
    return int(pixels.size());
}

/// Traces the corner samples (corner_run) of the corners in `corners`, a rectangle of the
/// (width + 1) x (height + 1) lattice of pixel corners, into `out` (3 floats each, row by row).
void trace_corners(PreparedRender& prepared, const Tile& corners, float* out, RayCounts& counts,
                   const RenderProgress* cancel) {
    static thread_local std::vector<std::uint32_t> all;
    const std::size_t n = std::size_t(corners.width()) * std::size_t(corners.height());
    if (all.size() < n) {
        all.resize(n);
        std::iota(all.begin(), all.end(), 0u);
    }
    prepared.render_samples(corners, corner_run(), all.data(), int(n), out, counts, cancel);
}

/// Round 0 from traced corners into dense tallies (dense_tallies): each pixel of t.tile takes
/// its four corners from `rgb`, the corners of the rectangle `corners` of the corner lattice.
void tally_corners(const float* rgb, const Tile& corners, TileTallies& t) {
    const std::size_t row = std::size_t(corners.width());
    for (int y = t.tile.y0; y < t.tile.y1; ++y)
        for (int x = t.tile.x0; x < t.tile.x1; ++x)
            t.tallies[std::size_t(y - t.tile.y0) * std::size_t(t.tile.width()) + std::size_t(x - t.tile.x0)] =
                corner_tally(rgb, row, std::size_t(y - corners.y0) * row + std::size_t(x - corners.x0));
}

/// The neighbour rule's flags (AdaptiveRule::above) of the pixels of `tile` from their corners
/// alone, into `above` (the whole image's flags, row by row): the spread corner_tally's
/// tallies would have (CornerQuad, without colour sums). `rgb`: the (w + 1) x (h + 1)
/// corner lattice.
void corner_flags(const AdaptiveRule& rule, const float* rgb, int w, const Tile& tile, std::uint8_t* above) {
    const std::size_t row = std::size_t(w) + 1;
    for (int y = tile.y0; y < tile.y1; ++y) {
        const float* top = rgb + (std::size_t(y) * row + std::size_t(tile.x0)) * 3;
        const float* bottom = top + row * 3;
        std::uint8_t* out = above + std::size_t(y) * std::size_t(w) + std::size_t(tile.x0);
        for (int x = 0; x < tile.width(); ++x, top += 3, bottom += 3) {
            const CornerQuad q = CornerQuad::of<false>(top, top + 3, bottom, bottom + 3);
            out[x] = rule.above(q.scaled_variance(), q.n);
        }
    }
}

/// Whether each tally's error is above its stopping point (AdaptiveRule::above), in order.
void mark_above(const AdaptiveRule& rule, const std::vector<PixelTally>& tallies, std::uint8_t* above) {
    for (std::size_t i = 0; i < tallies.size(); ++i) above[i] = rule.above(tallies[i]);
}

/// spread_near of the pixels of `inner` (inside `outer`, whose round-0 `above` flags, 0 or 1,
/// are `above`, row by row): its own error or one of its neighbours' (those inside `outer`)
/// above. The 3 x 3 window is taken in two passes: each row's flags with their left and right
/// neighbours', then three such rows.
void mark_spread(const Tile& outer, const std::uint8_t* above, const Tile& inner, std::vector<std::uint8_t>& spread_near) {
    const std::size_t ow = std::size_t(outer.width()), w = std::size_t(inner.width());
    const int ya = std::max(outer.y0, inner.y0 - 1), yb = std::min(outer.y1, inner.y1 + 1);
    static thread_local std::vector<std::uint8_t> rows;  // rows ya .. yb - 1, columns of inner
    rows.resize(std::size_t(yb - ya) * w);
    for (int y = ya; y < yb; ++y) {
        const std::uint8_t* a = above + std::size_t(y - outer.y0) * ow;
        std::uint8_t* h = &rows[std::size_t(y - ya) * w];
        for (int x = inner.x0; x < inner.x1; ++x) {
            const std::size_t i = std::size_t(x - outer.x0);
            h[x - inner.x0] = std::uint8_t(a[i] | (x > outer.x0 ? a[i - 1] : 0) | (x + 1 < outer.x1 ? a[i + 1] : 0));
        }
    }
    for (int y = inner.y0; y < inner.y1; ++y) {
        const std::uint8_t* mid = &rows[std::size_t(y - ya) * w];
        const std::uint8_t* up = y > ya ? mid - w : mid;
        const std::uint8_t* down = y + 1 < yb ? mid + w : mid;
        std::uint8_t* out = &spread_near[std::size_t(y - inner.y0) * w];
        for (std::size_t x = 0; x < w; ++x) out[x] = std::uint8_t(up[x] | mid[x] | down[x]);
    }
}

/// The means of dense tallies (dense_tallies) into rgb, row by row.
void write_means(const TileTallies& t, float* rgb) {
    for (std::size_t p = 0; p < t.tallies.size(); ++p) {
        const ColorT<double> m = t.tallies[p].mean();
        rgb[p * 3 + 0] = float(m.x), rgb[p * 3 + 1] = float(m.y), rgb[p * 3 + 2] = float(m.z);
    }
}

/// Calls f(x, y, tally) for every pixel of t.tile in row order: its own PixelTally when it
/// has one, otherwise (a pixel that stopped at its corners) the CornerQuad of its corners
/// from the whole image's corner lattice `corner_rgb` ((w + 1) x (h + 1) colours): both
/// give n, mean(), standard_error() and image_error_squared(), to the same bits.
template <class F>
void for_each_pixel(const TileTallies& t, const float* corner_rgb, int w, F&& f) {
    const std::size_t row = std::size_t(w) + 1;
    std::size_t k = 0;  // the next tally: t.pixel is ascending
    std::uint32_t p = 0;
    for (int y = t.tile.y0; y < t.tile.y1; ++y)
        for (int x = t.tile.x0; x < t.tile.x1; ++x, ++p) {
            if (k < t.pixel.size() && t.pixel[k] == p) {
                f(x, y, t.tallies[k++]);
            } else {
                const float* top = corner_rgb + (std::size_t(y) * row + std::size_t(x)) * 3;
                f(x, y, CornerQuad::of(top, top + 3, top + row * 3, top + row * 3 + 3));
            }
        }
}

/// Round 1's tallies of a tile whose pixels all stand at their corners (a corner round 0): the
/// pixels the neighbour rule sends on (their own flag in `above_image`, the whole image's, or
/// one of their eight neighbours') get a tally from their corners, in pixel order; `t` keeps
/// its vectors' memory from tile to tile.
void start_round_one(TileTallies& t, const std::uint8_t* above_image, const float* corner_rgb, int w, int h) {
    static thread_local std::vector<std::uint8_t> near;
    near.resize(std::size_t(t.tile.width()) * std::size_t(t.tile.height()));
    mark_spread({0, 0, w, h}, above_image, t.tile, near);
    const std::size_t taking = std::size_t(std::count_if(near.begin(), near.end(), [](std::uint8_t v) { return v != 0; }));
    t.tallies.clear(), t.pixel.clear(), t.spread_near.clear(), t.took_last.clear();
    t.tallies.reserve(taking), t.pixel.reserve(taking), t.spread_near.reserve(taking);
    const std::size_t row = std::size_t(w) + 1;
    std::uint32_t p = 0;
    for (int y = t.tile.y0; y < t.tile.y1; ++y)
        for (int x = t.tile.x0; x < t.tile.x1; ++x, ++p)
            if (near[p]) {
                t.tallies.push_back(corner_tally(corner_rgb, row, std::size_t(y) * row + std::size_t(x)));
                t.pixel.push_back(p);
                t.spread_near.push_back(1);
            }
}

/// A tile's pixels once its rounds are over: the means into `image`, the sample counts and
/// standard errors into `map` (when not null); returns the tile's sum of samples, sets `error`
/// to its pixels' shares of the image's squared error and `at_cap` to its pixels that reached
/// the cap still above their stopping point (the closing line says the cap cut them short).
double finish_tile(const TileTallies& t, const float* corner_rgb, int w, const AdaptiveRule& rule, Framebuffer& image,
                   Framebuffer* map, double& error, std::uint64_t& at_cap) {
    double n = 0;
    error = 0;
    at_cap = 0;
    for_each_pixel(t, corner_rgb, w, [&](int x, int y, const auto& tally) {
        if (tally.n >= rule.cap && rule.above(tally.scaled_variance(), tally.n)) ++at_cap;
        const ColorT<double> mean = tally.mean();
        float* px = image.pixel(x, y);
        px[0] = float(mean.x), px[1] = float(mean.y), px[2] = float(mean.z);
        if (map) {
            float* m = map->pixel(x, y);
            m[0] = float(tally.n);
            m[1] = float(tally.standard_error());
            m[2] = 0.f;
        }
        n += tally.n;
        error += tally.image_error_squared();
    });
    return n;
}

}  // namespace

void render_adaptive_tile(PreparedRender& prepared, const Tile& tile, float* rgb, RayCounts& counts,
                          const RenderProgress* cancel) {
    // Round 0 on the tile and the ring around it (inside the image): the neighbours' first
    // samples are the ones their own tiles take, so the rule sees what a whole-image render sees.
    const Tile ring{std::max(0, tile.x0 - 1), std::max(0, tile.y0 - 1), std::min(prepared.width, tile.x1 + 1),
                    std::min(prepared.height, tile.y1 + 1)};
    TileTallies outer = dense_tallies(ring);
    if (prepared.adaptive.corner_round()) {
        // The ring's corners: the same corner samples the neighbouring tiles trace.
        const Tile corners{ring.x0, ring.y0, ring.x1 + 1, ring.y1 + 1};
        std::vector<float> rgb_corners(std::size_t(corners.width()) * std::size_t(corners.height()) * 3);
        trace_corners(prepared, corners, rgb_corners.data(), counts, cancel);
        tally_corners(rgb_corners.data(), corners, outer);
    } else {
        refine(prepared, 0, outer, counts, cancel);
    }
    TileTallies t = dense_tallies(tile);
    for (int y = tile.y0; y < tile.y1; ++y)
        std::copy_n(&outer.tallies[std::size_t(y - ring.y0) * std::size_t(ring.width()) + std::size_t(tile.x0 - ring.x0)],
                    tile.width(), &t.tallies[std::size_t(y - tile.y0) * std::size_t(tile.width())]);
    std::vector<std::uint8_t> above(outer.tallies.size());
    mark_above(prepared.adaptive, outer.tallies, above.data());
    mark_spread(ring, above.data(), tile, t.spread_near);
    for (int r = 1; refine(prepared, r, t, counts, cancel) > 0; ++r) {
    }
    write_means(t, rgb);
}

Framebuffer render_adaptive_image(PreparedRender& prepared, Parallelism& par, RenderProgress* progress) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const AdaptiveStop& stop = prepared.stop;
    const auto out_of_time = [&] {
        return stop.time_limit > 0 && std::chrono::duration<double>(Clock::now() - start).count() >= stop.time_limit;
    };
    const int w = prepared.width, h = prepared.height;
    const int nx = (w + kTileSize - 1) / kTileSize, ny = (h + kTileSize - 1) / kTileSize;
    // The corner lattice of a corner round 0, (w + 1) x (h + 1) corners, each traced once: a
    // tile traces the corners at its pixels' top left, and those of the image's last column
    // and row when it borders them.
    const bool corners_first = prepared.adaptive.corner_round();
    // Not zero-filled: every corner is written by the tile that traces it, so each page is
    // first touched by the thread that fills it, not zeroed first by this one (3.7 MB at
    // 640x480; whole process 2 % faster on whitted, docs/adaptive-sampling.md), in huge pages.
    LargeFillLaterVec<float> corner_rgb(corners_first ? std::size_t(w + 1) * std::size_t(h + 1) * 3 : 0);
    // With a corner round, a pixel gets a tally (120 bytes) only when it takes round 1: most
    // pixels stop at their corners, and their tallies are made from corner_rgb when read
    // (whitted.cfg at 640x480: allocating and zeroing a tally for every pixel was a twelfth
    // of the render at -j2). Without one, every pixel has a tally from round 0, first touched
    // by the thread that uses it.
    std::vector<TileTallies> tiles(std::size_t(nx) * std::size_t(ny));
    par.for_each_index(tiles.size(), 1, [&](std::size_t i) {
        const Tile tile = tile_rect(w, h, int(i));
        if (corners_first) tiles[i].tile = tile;
        else tiles[i] = dense_tallies(tile);
    });

    // Tiles in an interleaved order (a stride near n / golden ratio, prime to n): the work of
    // later rounds sits in a few regions (edges, penumbrae), and a loop that hands out halves
    // of its range left one thread holding a whole region while the other ran out
    // (scenes/soft_shadows.cfg at 640x480, T = 0.0025: -j2 was 1.25x faster than -j1 with the
    // tiles in order, 1.84x interleaved).
    std::vector<int> order(tiles.size());
    for (std::size_t k = 0, stride = interleave_stride(order.size()); k < order.size(); ++k)
        order[k] = int((k * stride) % order.size());

    Framebuffer image = Framebuffer::uninitialized(w, h);
    // The sample map only when someone reads it: a second image of the picture's size, whose
    // first touch of every page is paid on the render's clock.
    const bool keep_map = prepared.keep_sample_map;
    Framebuffer map = keep_map ? Framebuffer::uninitialized(w, h) : Framebuffer{};
    std::vector<double> tile_samples(tiles.size());  // summed in tile order after: the same for any -j
    // Nothing to stop at between rounds (no image target, no clock) after a corner round: each
    // tile runs its rounds and is finished in one go (the r == 1 step below).
    const bool fused = corners_first && stop.target_error <= 0 && stop.time_limit <= 0;
    bool fused_done = false;

    AdaptiveSummary summary;
    // The image's estimated RMSE from each tile's sum of its pixels' shares: the tiles' sums
    // are taken in parallel and added in tile order, the same figure for every -j.
    std::vector<double> tile_error(tiles.size());
    std::vector<std::uint64_t> tile_at_cap(tiles.size());
    const auto rmse_of_tiles = [&] {
        double sum = 0;
        for (const double e : tile_error) sum += e;
        return std::sqrt(sum / (double(w) * double(h)));
    };
    const auto estimated_rmse = [&] {
        par.for_each_index(tiles.size(), 1, [&](std::size_t i) {
            double sum = 0;
            for_each_pixel(tiles[i], corner_rgb.data(), w, [&](int, int, const auto& p) { sum += p.image_error_squared(); });
            tile_error[i] = sum;
        });
        return rmse_of_tiles();
    };
    // Wall time by phase (AdaptivePhases): each lap adds the time since the last to one phase.
    auto lap_start = Clock::now();
    const auto lap = [&lap_start](double& phase) {
        const auto now = Clock::now();
        phase += std::chrono::duration<double>(now - lap_start).count();
        lap_start = now;
    };
    AdaptivePhases& phases = summary.seconds;
    for (int r = 0;; ++r) {
        if (r == 0 && corners_first) {
            // The corners in blocks of kCornerBlock x kCornerBlock pixels: a block's corners
            // are one stream of about a thousand rays, where a tile's 289 left the stages' fixed
            // cost per stream a quarter of the round (a corner's colour does not depend on the
            // stream that traces it).
            const int bx = (w + kCornerBlock - 1) / kCornerBlock, by = (h + kCornerBlock - 1) / kCornerBlock;
            const std::size_t blocks = std::size_t(bx) * std::size_t(by), stride = interleave_stride(blocks);
            par.for_each_index(blocks, 1, [&](std::size_t k) {
                if (progress && progress->cancelled()) return;
                const int b = int((k * stride) % blocks);
                const int x0 = (b % bx) * kCornerBlock, y0 = (b / bx) * kCornerBlock;
                const int x1 = std::min(w, x0 + kCornerBlock), y1 = std::min(h, y0 + kCornerBlock);
                const Tile own{x0, y0, x1 + (x1 == w), y1 + (y1 == h)};
                static thread_local std::vector<float> rgb;
                rgb.resize(std::size_t(own.width()) * std::size_t(own.height()) * 3);
                RayCounts counts;
                trace_corners(prepared, own, rgb.data(), counts, progress);
                for (int y = own.y0; y < own.y1; ++y)
                    std::copy_n(&rgb[std::size_t(y - own.y0) * std::size_t(own.width()) * 3], std::size_t(own.width()) * 3,
                                &corner_rgb[(std::size_t(y) * std::size_t(w + 1) + std::size_t(own.x0)) * 3]);
                if (progress) {
                    // Progress counts tiles (tiles_total) and a block holds up to 2 x 2 of them:
                    // counted as one, round 0 ended at a quarter of the bar.
                    progress->add(counts);
                    const int tiles = ((x1 - x0 + kTileSize - 1) / kTileSize) * ((y1 - y0 + kTileSize - 1) / kTileSize);
                    progress->tiles_done += tiles - 1;
                }
            });
            summary.rounds = 1;
            lap(phases.corners);
            if (progress && progress->cancelled()) {
                // Tiles skipped by the cancel left their corners unwritten: the final pass reads zeros.
                std::fill(corner_rgb.begin(), corner_rgb.end(), 0.f);
                break;
            }
            if (out_of_time()) {
                summary.time_limited = true;
                break;
            }
            if (stop.target_error > 0 && estimated_rmse() <= stop.target_error) break;
            continue;
        }
        if (r == 1) {
            // The neighbour rule reads round 0 across tiles: each pixel's above-T flag, in an
            // image of bytes, then each tile's pixels look at their eight neighbours there.
            // Not zero-filled: every pixel's flag is written below.
            std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> above_image(std::size_t(w) * std::size_t(h));
            par.for_each_index(tiles.size(), 1, [&](std::size_t i) {
                if (corners_first) {  // every pixel still stands at its corners
                    corner_flags(prepared.adaptive, corner_rgb.data(), w, tiles[i].tile, above_image.data());
                    return;
                }
                for_each_pixel(tiles[i], corner_rgb.data(), w, [&](int x, int y, const auto& p) {
                    above_image[std::size_t(y) * std::size_t(w) + std::size_t(x)] = prepared.adaptive.above(p.scaled_variance(), p.n);
                });
            });
            if (fused) {
                // Each tile from its round 1 to its end, then its pixels, in one go on one thread:
                // its tallies live in that thread's scratch (reused from tile to tile: no fresh
                // pages for them, no second pass over the image), and the results are the same
                // as the rounds' loop below and the final pass give.
                lap(phases.neighbour_rule);
                std::atomic<int> last_round{0};
                par.for_each_index(order.size(), 1, [&](std::size_t k) {
                    const std::size_t i = std::size_t(order[k]);
                    static thread_local TileTallies t;
                    t.tile = tiles[i].tile;
                    t.tallies.clear(), t.pixel.clear(), t.spread_near.clear(), t.took_last.clear();
                    RayCounts counts;
                    if (!(progress && progress->cancelled())) {
                        start_round_one(t, above_image.data(), corner_rgb.data(), w, h);
                        for (int q = 1; refine(prepared, q, t, counts, progress) > 0; ++q)
                            for (int seen = last_round.load(); seen < q && !last_round.compare_exchange_weak(seen, q);) {
                            }
                    }
                    // A tile the cancel skipped has no tallies: its pixels keep their corners' means.
                    tile_samples[i] = finish_tile(t, corner_rgb.data(), w, prepared.adaptive, image,
                                                  keep_map ? &map : nullptr, tile_error[i], tile_at_cap[i]);
                    if (progress) progress->add_rays(counts);
                });
                if (last_round > 0) summary.rounds = last_round + 1;
                lap(phases.rounds);
                fused_done = true;
                break;
            }
            par.for_each_index(tiles.size(), 1, [&](std::size_t i) {
                TileTallies& t = tiles[i];
                if (!corners_first) {
                    mark_spread({0, 0, w, h}, above_image.data(), t.tile, t.spread_near);
                    return;
                }
                // The pixels that take round 1 get their tallies, from their corners.
                start_round_one(t, above_image.data(), corner_rgb.data(), w, h);
            });
            lap(phases.neighbour_rule);
        }
        std::atomic<int> refined{0};
        // Without an image target or a clock, nothing after round 1 looks beyond its own
        // pixel: each tile then runs all its remaining rounds in one go, without waiting at
        // the end of every round for the tile that holds the most work (same picture).
        const bool to_the_end = r == 1 && stop.target_error <= 0 && stop.time_limit <= 0;
        std::atomic<int> last_round{r};
        par.for_each_index(order.size(), 1, [&](std::size_t k) {
            const int index = order[k];
            if (progress && progress->cancelled()) return;
            // The first round covers the image whatever the clock says (a picture to show); a
            // later one may stop part-way, its pixels keeping the samples they have.
            if (r > 0 && out_of_time()) return;
            RayCounts counts;
            for (int q = r; refine(prepared, q, tiles[std::size_t(index)], counts, progress) > 0; ++q) {
                ++refined;
                for (int seen = last_round.load(); seen < q && !last_round.compare_exchange_weak(seen, q);) {
                }
                if (!to_the_end) break;
            }
            if (progress) r == 0 ? progress->add(counts) : progress->add_rays(counts);
        });
        // Round 0 without corners is the first round of samples: counted with the rounds.
        lap(phases.rounds);
        if (refined == 0) break;
        summary.rounds = last_round + 1;
        if (to_the_end) break;
        if (progress && progress->cancelled()) break;
        if (out_of_time()) {
            summary.time_limited = true;
            break;
        }
        if (stop.target_error > 0 && estimated_rmse() <= stop.target_error) break;
    }

    if (!fused_done) {
        par.for_each_index(tiles.size(), 1, [&](std::size_t i) {
            tile_samples[i] = finish_tile(tiles[i], corner_rgb.data(), w, prepared.adaptive, image,
                                          keep_map ? &map : nullptr, tile_error[i], tile_at_cap[i]);
        });
        lap(phases.final_pass);
    }
    double samples = 0;  // camera rays: a corner is traced once for the four pixels it bounds
    if (corners_first) samples = double(w + 1) * double(h + 1) - double(kFirstRoundSamples) * double(w) * double(h);
    for (const double n : tile_samples) samples += n;
    summary.mean_spp = samples / (double(w) * double(h));
    summary.cap = prepared.adaptive.cap;
    summary.threshold = prepared.adaptive.threshold;
    summary.target_error = stop.target_error;
    for (const std::uint64_t n : tile_at_cap) summary.above_at_cap += n;
    summary.estimated_rmse = rmse_of_tiles();
    prepared.last_adaptive = summary;
    prepared.sample_map = std::move(map);
    return image;
}

}  // namespace streamrt
