#pragma once
// The stages of the stream pipeline, specialised at compile time on the features a scene
// uses. Read run_chunk(), trace_generation() and trace_slice() top to bottom: they are the
// whole algorithm for one chunk of a tile. The shade stage is in shade_stage.h, the buffers
// in workspace.h, the cutting of generations into slices in slicing.h.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "kernels/kernel_table.h"
#include "kernels/ray_stream.h"
#include "kernels/shade_job.h"
#include "render/render_stats.h"
#include "render/sampling.h"
#include "shapes/shapes.h"
#include "stream/profile.h"
#include "stream/sample_request.h"
#include "stream/shade_mode.h"
#include "stream/shade_stage.h"
#include "stream/slicing.h"
#include "stream/stream_scene.h"
#include "stream/workspace.h"

namespace streamrt {

template <bool kLighting, bool kShadows, bool kReflect, bool kRefract, bool kBounce, bool kJitter>
struct PipelineStages {
    static constexpr bool kSecondary = kReflect || kRefract || kBounce;
    using Shade = ShadeStage<kLighting, kShadows, kReflect, kRefract, kBounce>;

    /// generate: camera rays for pixels [first, first + n_pixels) of the request's list
    /// (SampleRequest), its run of samples per pixel, consecutive, so a pixel's samples share
    /// a packet. Each ray's accumulation slot and weight are the request's (slot_of, weight).
    static void generate(const StreamScene& sc, const KernelTable& kt, const Tile& tile, const SampleRequest& req,
                         int first, int n_pixels, Workspace& ws) {
        RayStream& rays = ws.current;
        GenerateScratch& g = ws.generate;
        const int count = req.run.count;
        const std::size_t n = std::size_t(n_pixels) * std::size_t(count);
        rays.reserve(n);
        const bool lens = sc.features.lens;  // one scene-wide choice: the thin-lens kernel
        g.reserve(n, lens);
        // Integer bookkeeping (pixel of each ray, sample number, lattice cell) in scalar code;
        // the hashing, jitter and camera directions in the SIMD kernel.
        const int cols = grid_columns(count);
        const auto image_pixel = [&](int p) {  // the hash key (a corner's, for a corner run)
            return sample_key(req.run, tile.x0 + p % tile.width(), tile.y0 + p / tile.width(), sc.settings.width);
        };
        std::size_t i = 0;
        for (int q = first; q < first + n_pixels; ++q) {
            const int p = req.pixel(q);
            const float x = float(tile.x0 + p % tile.width()), y = float(tile.y0 + p / tile.width());
            const std::uint32_t key_pixel = image_pixel(p);  // once per pixel, not per sample
            int cx = 0, cy = 0;
            for (int j = 0; j < count; ++j, ++i) {
                g.px[i] = x;
                g.py[i] = y;
                if constexpr (kJitter) {
                    g.key_pixel[i] = key_pixel;
                    g.key_sample[i] = std::uint32_t(req.run.first + j);
                    g.cell_x[i] = float(cx);
                    g.cell_y[i] = float(cy);
                    if (++cx == cols) cx = 0, ++cy;
                }
                rays.pixel[i] = req.slot_of(q - first, j, p);
            }
        }
        rays.count = i;
        // Apart: a byte store in the loop above may alias anything, and the compiler then
        // reloaded every array's address at every ray (6 % of whitted's render at 16 spp).
        std::fill_n(rays.kind.begin(), i, std::uint8_t(RayKind::Primary));
        if (lens) {  // a second pass, so a pinhole camera runs exactly the loop above
            std::size_t k = 0;
            for (int q = first; q < first + n_pixels; ++q) {
                const std::uint32_t pixel = image_pixel(req.pixel(q));
                const LensCells cells(count, pixel);  // render/sampling.h
                for (int j = 0; j < count; ++j, ++k) {
                    g.key_pixel[k] = pixel;  // also at spp = 1: the lens hashes need them
                    g.key_sample[k] = std::uint32_t(req.run.first + j);
                    int lx, ly;
                    cells.cell(j, lx, ly);
                    g.lens_x[k] = float(lx);
                    g.lens_y[k] = float(ly);
                }
            }
        }
        const GenerateJob job{.count = n,
                              .px = g.px.data(),
                              .py = g.py.data(),
                              .cell_x = g.cell_x.data(),
                              .cell_y = g.cell_y.data(),
                              .key_pixel = g.key_pixel.data(),
                              .key_sample = g.key_sample.data(),
                              .pattern = int(sc.settings.pattern),
                              .jitter = kJitter && !req.run.corner,
                              .cols = float(cols),
                              .rows = float(count / cols),
                              .camera = &sc.camera,
                              .weight = req.weight(),
                              .out = append_view(rays),
                              .lens_cell_x = g.lens_x.data(),
                              .lens_cell_y = g.lens_y.data(),
                              .fixed_offset = req.run.corner ? 0.f : 0.5f,
                              .sequence = kJitter && uses_sequence(sc.settings.pattern, req.run)};
        (lens ? kt.generate_lens : kt.generate)(job);
        if (sc.features.keys) {
            // Each camera ray's key (render/sampling.h camera_key), from its image pixel and
            // sample number: the rays of a pixel are its samples in order.
            rays.reserve_keys();
            std::size_t k = 0;
            for (int q = first; q < first + n_pixels; ++q) {
                const std::uint32_t pixel = image_pixel(req.pixel(q));
                for (int j = 0; j < count; ++j, ++k)
                    rays.key[k] = camera_key(sc.settings.degree, sc.settings.spp, pixel, req.run.first + j);
            }
        }
    }

    /// intersect: closest hit of every ray, one SIMD kernel per shape kind present.
    static void intersect(const StreamScene& sc, const KernelTable& kt, int depth, RayStream& rays,
                          AlignedVec<std::int32_t>& object, MeshHits& mesh_hits, StageFigures* fig) {
        rays.pad_tail();
        if (object.size() < rays.capacity()) object.resize(rays.capacity());
        std::fill_n(object.begin(), rays.count, -1);
        RayView view = view_of(rays);
        if (sc.has_meshes) {  // mesh kernels report the triangle and barycentrics here
            mesh_hits.reserve(rays.capacity());
            view.prim = mesh_hits.prim.data();
            view.bu = mesh_hits.u.data();
            view.bv = mesh_hits.v.data();
            // Diffuse bounces scatter at once: their packets may hand over to single rays from
            // the first bounce (glass bunny in a box, degree 6: intersect 0.952x, min 0.954x).
            const int hybrid_from = sc.features.bounce ? 1 : accel::kMeshHybridFromDepth;
            view.single_ray_lanes = depth >= hybrid_from ? sc.mesh_hybrid_lanes : 0;
        }
        if (sc.accel) {  // the object hierarchy (stream/stream_accel.h)
            sc.accel->closest(kt, view, object.data(), rays.count > 0 && rays.kind[0] == std::uint8_t(RayKind::Primary));
            if (fig) fig->lanes_used += rays.count, fig->lanes_total += rays.count;
        }
        for (int k = 0; !sc.accel && k < kShapeKindCount; ++k) {
            const auto& group = sc.groups[k];
            if (group.empty()) continue;
            if (sc.group_bounded[k])
                kt.closest_culled[k](view, object.data(), group.data(), sc.group_bounds[k].data(), group.size());
            else
                kt.closest[k](view, object.data(), group.data(), group.size());
            if (fig) {
                fig->lanes_used += rays.count;
                fig->lanes_total += stage_detail::lanes_for(rays.count, shape_computes_in_double(ShapeKind(k)) ? kt.float_lanes / 2 : kt.float_lanes);
            }
        }
        // CSG objects after the others: their spans start from the ray's closest hit so far.
        if (sc.csg) sc.csg->closest(kt, view, object.data());
    }

    /// occlusion: any-hit kernels per shape kind (early exit per packet); the caller adds the
    /// light of the unblocked shadow rays (trace_slice).
    static void occlusion(const StreamScene& sc, const KernelTable& kt, ShadowStream& shadows, StageFigures* fig) {
        shadows.pad_tail();
        if (sc.accel) {  // the object hierarchy (stream/stream_accel.h)
            sc.accel->any(kt, view_of(shadows));
            if (fig) fig->lanes_used += shadows.count, fig->lanes_total += shadows.count;
        }
        for (int k = 0; !sc.accel && k < kShapeKindCount; ++k) {
            const auto& group = sc.groups[k];
            if (group.empty()) continue;
            if (sc.group_bounded[k])
                kt.any_culled[k](view_of(shadows), group.data(), sc.group_bounds[k].data(), group.size());
            else
                kt.any[k](view_of(shadows), group.data(), group.size());
            if (fig) {
                fig->lanes_used += shadows.count;
                fig->lanes_total += stage_detail::lanes_for(shadows.count, shape_computes_in_double(ShapeKind(k)) ? kt.float_lanes / 2 : kt.float_lanes);
            }
        }
        if (sc.csg) sc.csg->any(kt, view_of(shadows));  // the rays still open after the others
    }

    /// What the stages of one chunk share.
    struct Chunk {
        const StreamScene& sc;
        const KernelTable& kt;
        const Tile& tile;
        Workspace& ws;
        float* accum;
        RayCounts& counts;
        StreamProfile* profile;
        ShadeMode shade_mode;
        std::size_t slice_rays;  ///< the most rays traced at once
        std::size_t slots;       ///< accumulation slots (accum holds 3 floats each; rays' `pixel`)
        int samples_per_slot;    ///< the samples a slot sums (SampleRequest): rays weigh its reciprocal
        StageFigures* fig(Stage s) const { return profile ? &profile->stages[int(s)] : nullptr; }
    };

    /// One slice of generation `depth`: intersect, shade, occlusion; the rays it spawns (at
    /// most two per ray) go to `spawned`.
    static void trace_slice(const Chunk& c, int depth, RayStream& rays, RayStream& spawned) {
        const StreamScene& sc = c.sc;
        Workspace& ws = c.ws;
        std::swap(ws.next, spawned);  // the shade stage appends to ws.next
        // This generation's row of the profile (a slice holds one generation only).
        GenerationFigures* const gen = c.profile ? &c.profile->generation(depth) : nullptr;
        {
            StageTimer timer(c.fig(Stage::Intersect), gen ? &gen->intersect_ns : nullptr);
            intersect(sc, c.kt, depth, rays, ws.object, ws.mesh_hits, c.fig(Stage::Intersect));
            if (c.profile) {
                c.fig(Stage::Intersect)->rays_in += rays.count, c.fig(Stage::Intersect)->rays_out += rays.count;
                gen->rays += rays.count;
            }
        }
        if (c.profile)  // by kind, outside the stage's time
            for (std::size_t i = 0; i < rays.count; ++i) {
                const RayKind kind = RayKind(rays.kind[i]);
                (kind == RayKind::Primary     ? gen->primary
                 : kind == RayKind::Reflected ? gen->reflected
                 : kind == RayKind::Refracted ? gen->refracted
                                              : gen->diffuse) += 1;
            }
        {
            StageTimer timer(c.fig(Stage::Shade));
            // Room for every ray spawning every child and a shadow ray per light.
            ws.next.reserve(kSecondary ? rays.count * Shade::kChildrenPerRay : 0);
            if (sc.features.keys) ws.next.reserve_keys();
            // Area lights send `samples` shadow rays each (StreamScene::shadow_rays_per_hit).
            if constexpr (kShadows) ws.shadows.reserve(rays.count * sc.shadow_rays_per_hit);
            if (c.shade_mode == ShadeMode::Scalar)
                Shade::shade(sc, rays, ws.object, ws.mesh_hits, depth, c.samples_per_slot, ws.next, ws.shadows,
                             ws.sorted, c.accum, c.counts);
            else
                Shade::shade_sorted(sc, c.kt, rays, ws.object, depth, c.samples_per_slot, ws, c.accum, c.counts,
                                    c.shade_mode == ShadeMode::Gathered);
            if (kShadows && c.shade_mode == ShadeMode::Gathered)
                Shade::order_shadows_by_pixel(ws, rays, c.slots);
            if (c.profile) {
                c.fig(Stage::Shade)->rays_in += rays.count;
                c.fig(Stage::Shade)->rays_out += ws.next.count + (kShadows ? ws.shadows.count : 0);
            }
        }
        if constexpr (kShadows) {
            StageTimer timer(c.fig(Stage::Occlusion), gen ? &gen->occlusion_ns : nullptr);
            c.counts.shadow += ws.shadows.count;
            occlusion(sc, c.kt, ws.shadows, c.fig(Stage::Occlusion));
            Shade::add_shadowed_locals(ws, rays, c.accum);
            if (c.profile) {
                c.fig(Stage::Occlusion)->rays_in += ws.shadows.count;
                gen->shadow_rays += ws.shadows.count;
                for (std::size_t i = 0; i < ws.shadows.count; ++i) c.fig(Stage::Occlusion)->rays_out += ws.shadows.t_max[i] > 0.f;
            }
        }
        std::swap(ws.next, spawned);
        rays.count = 0;  // traced
    }

    /// Traces generation `depth` and everything it spawns, deepest first: a generation of
    /// more than slice_rays rays is cut into slices, and each slice's descendants are traced
    /// before the next slice. A slice spawns at most twice its rays, so the rays held are at
    /// most 2 x slice_rays for each generation on the way down, whatever the depth, instead
    /// of 2^depth; a generation traced whole gives its buffer back before its children are
    /// traced, so chains of such generations reuse the same few buffers.
    /// The slices hold whole pixels (cut_into_slices) and pixels do not interact, so each
    /// pixel gets the same terms as when every generation is traced whole; one ray at a time
    /// (scalar shading) in the same order, bit for bit. Only a pixel with more than
    /// slice_rays rays in one generation is cut itself. Either way, the order is fixed by the
    /// tile's content: the same picture for every -j.
    static void trace_generation(const Chunk& c, int depth, RayStream&& rays) {
        Workspace& ws = c.ws;
        RayStream gen = std::move(rays);
        if (gen.count <= c.slice_rays) {  // whole: no copy
            RayStream spawned = ws.take();
            trace_slice(c, depth, gen, spawned);
            ws.give(std::move(gen));
            descend(c, depth, std::move(spawned));
            return;
        }
        const std::vector<std::size_t> bounds =
            stage_detail::cut_into_slices(gen, ws.regroup, c.slice_rays, c.slots,
                                          ws.pixel_rays, ws.pixel_slice, c.sc.features.keys);
        for (std::size_t k = 0; k + 1 < bounds.size(); ++k) {
            RayStream slice = ws.take(), spawned = ws.take();
            stage_detail::copy_rays(gen, bounds[k], bounds[k + 1] - bounds[k], slice, c.sc.features.keys);
            trace_slice(c, depth, slice, spawned);
            ws.give(std::move(slice));
            descend(c, depth, std::move(spawned));
        }
        gen.count = 0;
        ws.give(std::move(gen));
    }

    /// The rays generation `depth` spawned: traced, or (none) their buffer given back.
    static void descend(const Chunk& c, int depth, RayStream&& spawned) {
        if (kSecondary && spawned.count > 0) trace_generation(c, depth + 1, std::move(spawned));
        else c.ws.give(std::move(spawned));
    }

    /// The whole algorithm for one chunk of a tile: camera rays for pixels [first, first +
    /// n_pixels) of the request, then every generation they spawn (trace_generation), their
    /// light added into `accum` (the request's slots). slice_rays: the most rays traced at once.
    static void run_chunk(const StreamScene& sc, const KernelTable& kt, const Tile& tile, const SampleRequest& req,
                          int first, int n_pixels, Workspace& ws, float* accum, RayCounts& counts,
                          StreamProfile* profile, ShadeMode shade_mode, std::size_t slice_rays) {
        const Chunk c{sc, kt, tile, ws, accum, counts, profile, shade_mode, std::max<std::size_t>(1, slice_rays),
                      req.slots(n_pixels, tile), req.samples_per_slot()};
        {
            StageTimer timer(c.fig(Stage::Generate));
            generate(sc, kt, tile, req, first, n_pixels, ws);
            counts.primary += ws.current.count;
            if (profile) c.fig(Stage::Generate)->rays_out += ws.current.count, c.fig(Stage::Generate)->rays_in += std::uint64_t(n_pixels);
        }
        RayStream primary = ws.take();
        std::swap(primary, ws.current);
        trace_generation(c, 0, std::move(primary));
    }
};

}  // namespace streamrt
