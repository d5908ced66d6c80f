#pragma once
// A render job: a scene with the command line's overrides applied, the engine and its
// options. Built once here for every front end (the Python module; the command line).
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
    std::optional<int> width, height, spp, depth, degree, light_samples, threads, frame;
    std::optional<double> cutoff, exposure;
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
    SamplePattern sampler{};
    Calibration calibration{};
    ColorSpace colorspace{};
    Tonemap tonemap{};
    ExrPixels exr{};
    EngineKind engine{};
    Isa isa{};  ///< stream engine only
    accel::AccelMode accel{};
    ShadeMode shade{};

    /// f(name, value) for every field, in declaration order: the one list of them.
    template <class F>
    void for_each_field(F&& f) const {
        f("width", width), f("height", height), f("spp", spp), f("depth", depth), f("degree", degree);
        f("light_samples", light_samples), f("frame", frame), f("cutoff", cutoff), f("exposure", exposure);
        f("sampler", sampler), f("calibration", calibration), f("colorspace", colorspace), f("tonemap", tonemap);
        f("exr", exr), f("engine", engine), f("isa", isa), f("accel", accel), f("shade", shade);
    }
    static constexpr int kFields = 18;  ///< for_each_field's count (checked by the tests)
};
// Adding a field: list it in for_each_field and kFields, and update this size.
static_assert(sizeof(PixelSettings) == 64, "PixelSettings changed: list every field in for_each_field");

/// "width=640,height=480,spp=4,...": every field of PixelSettings, enums by their names,
/// numbers exactly (%.17g), the stream kernels' level as "none" for the recursive engine.
std::string settings_token(const PixelSettings& s);

/// Sets the override `name` from its text (the command line's spelling: "spp", "light_samples",
/// ...); false for a name that is not an override. UsageError for a bad value.
bool set_override(RenderOverrides& o, const std::string& name, const std::string& value);
/// The override names, comma-separated, for messages.
std::string override_names();

struct RenderJob {
    Scene scene;
    PixelSettings settings;  ///< what the pixels depend on beside the scene's files
    EngineKind engine = EngineKind::Stream;
    EngineOptions options;
    std::unique_ptr<StreamProfile> profile;  ///< when profiling (options.profile points to it)
    int threads = 0;                         ///< <= 0: all cores
};

/// Applies the overrides to the scene and checks them (UsageError: one line).
RenderJob build_render_job(Scene scene, const RenderOverrides& o, bool profile);

}  // namespace streamrt
