#pragma once
// A render job: a parsed scene, never changed, with the settings it is rendered with (the
// scene's own, the front end's overrides applied), the engine and its options. Built once
// here for every front end (the Python module; the command line).
#include <memory>
#include <optional>
#include <string>

#include "driver/render.h"
#include "kernels/kernel_table.h"
#include "scene/scene.h"
#include "scene/scene_bvh.h"
#include "stream/profile.h"
#include "stream/shade_mode.h"

namespace streamrt {

/// What a front end may override of a scene's settings (each unset: the scene's own).
struct RenderOverrides {
    std::optional<int> width, height, spp, depth, degree, light_samples, threads, frame, mesh_hybrid;
    std::optional<double> cutoff, exposure;
    /// Adaptive sampling (docs/adaptive-sampling.md): the pixels' threshold, the image's
    /// target error, the seconds after which refinement stops.
    std::optional<double> adaptive, target_error, time_limit;
    std::optional<std::string> sampler, engine, isa, accel, colorspace, tonemap, shade;
    std::optional<std::string> output;  ///< the file written (the scene's `image output=` otherwise)
};

/// Everything beside the scene's files that changes the pixels, or the file written, of a
/// render: its effective values once the overrides are applied. The settings token that
/// binds shard parts, checkpoint journals and frames to one render (settings_token) is made
/// from these fields and nothing else, through for_each_field: a field added to the struct
/// but not to that list fails the static_assert below, so no setting can be left out.
struct PixelSettings {
    int width = 0, height = 0, spp = 0, depth = 0, degree = 0;
    int light_samples = 0;  ///< 0: every area light's own samples= (part of the scene's files)
    int frame = -1;         ///< -1: a still picture
    double cutoff = 0, exposure = 1;
    double adaptive = 0, target_error = 0;  ///< 0: uniform sampling; 0: no image target
    SamplePattern sampler{};
    Calibration calibration{};
    ColorSpace colorspace{};
    Tonemap tonemap{};
    ExrPixels exr{};
    EngineKind engine{};
    Isa isa{};  ///< stream engine only
    accel::AccelMode accel{};
    ShadeMode shade{};
    int mesh_hybrid = 0;  ///< AccelConfig::mesh_hybrid_lanes (--mesh-hybrid)

    /// f(name, value) for every field, in declaration order: the one list of them.
    template <class F>
    void for_each_field(F&& f) const {
        f("width", width), f("height", height), f("spp", spp), f("depth", depth), f("degree", degree);
        f("light_samples", light_samples), f("frame", frame), f("cutoff", cutoff), f("exposure", exposure);
        f("adaptive", adaptive), f("target_error", target_error);
        f("sampler", sampler), f("calibration", calibration), f("colorspace", colorspace), f("tonemap", tonemap);
        f("exr", exr), f("engine", engine), f("isa", isa), f("accel", accel), f("shade", shade);
        f("mesh_hybrid", mesh_hybrid);
    }
    static constexpr int kFields = 21;  ///< for_each_field's count (checked by the tests)
};
// Adding a field: list it in for_each_field and kFields, and update this size.
static_assert(sizeof(PixelSettings) == 88, "PixelSettings changed: list every field in for_each_field");

/// Bumped whenever a change makes the same settings give other pixels, so that shard parts,
/// checkpoint journals and frames written by an older build are refused, not mixed with new
/// ones: the settings token starts with it. 2: adaptive sampling's stopping point became
/// T sqrt(n / 16) (2026-11-27). 3: an adaptive pixel's corners weigh a quarter of its own
/// samples in its mean (kCornerWeight); 4: its stopping point became T (n / 16)^(3/4) (both 2026-11-27).
/// 5: its spread became the mean of the channels' variances, and its corners weigh an eighth
/// (2026-11-28). 6: mesh hits lane by lane (the watertight test's double fallback, ties to the
/// lower triangle) and a uniform tile's pixels in Z order in scenes with a hierarchy: pixels
/// of mesh and object-tree scenes move by an ulp (2026-11-28).
inline constexpr int kPixelsRevision = 6;

/// "pixels=4,width=640,height=480,spp=4,...": kPixelsRevision, then every field of
/// PixelSettings, enums by their names, numbers exactly (%.17g), the stream kernels' level as
/// "none" for the recursive engine.
std::string settings_token(const PixelSettings& s);

/// Sets the override `name` from its text (the command line's spelling: "spp", "light_samples",
/// ...); false for a name that is not an override. UsageError for a bad value.
bool set_override(RenderOverrides& o, const std::string& name, const std::string& value);
/// The override names, comma-separated, for messages.
std::string override_names();

/// Where an adaptive render's cap (its spp, the most samples a pixel takes) came from, so
/// that a request the cap cut short can say which cap and how to raise it.
enum class AdaptiveCapFrom {
    Given,    ///< spp given with the request (--spp, spp=)
    Scene,    ///< the scene's spp
    Default,  ///< kDefaultAdaptiveCap: the scene's spp was 1, or a uniform count below it
};

struct RenderJob {
    /// The scene as read, immutable and shared (jobs made from one parsed scene share it). A
    /// front end may let go of it (reset) once the engine is prepared and nothing is prepared
    /// from it again: a prepared render holds what it reads (PreparedRender::reads_scene_objects).
    std::shared_ptr<const Scene> scene;
    /// The scene's settings with the overrides applied: what the engines render and the image
    /// is written with. `output` is the name as given: for frames a pattern (printf-style %d)
    /// whose name for a frame is made where the file is written.
    RenderSettings render_settings;
    PixelSettings settings;  ///< what the pixels depend on beside the scene's files
    EngineKind engine = EngineKind::Stream;
    EngineOptions options;
    std::unique_ptr<StreamProfile> profile;  ///< when profiling (options.profile points to it)
    int threads = 0;                         ///< <= 0: all cores
    AdaptiveCapFrom adaptive_cap_from = AdaptiveCapFrom::Scene;
};

/// The job for `scene` with the overrides applied to its settings (the scene is not
/// changed) and checked (UsageError: one line).
RenderJob build_render_job(std::shared_ptr<const Scene> scene, const RenderOverrides& o, bool profile);

/// The engine's set-up for the job's scene at `frame` (< 0: the scene as read; an animated
/// frame is a new scene, scene_at_frame), rendered with the job's settings.
std::unique_ptr<PreparedRender> prepare_job(const RenderJob& job, EngineKind engine, int frame);

/// Brings a set-up of the job's scene at frame `from` to frame `to` (only what changed is
/// re-derived). An animated scene's job must still hold its scene.
void update_job_frame(PreparedRender& prepared, const RenderJob& job, int from, int to);

}  // namespace streamrt
