#pragma once
// A render job: a scene with the command line's overrides applied, the engine and its
// options. Built once here for every front end (the Python module; the command line).
#include <memory>
#include <optional>
#include <string>

#include "driver/render.h"
#include "scene/scene.h"
#include "stream/profile.h"

namespace streamrt {

/// What a front end may override of a scene's settings (each unset: the scene's own).
struct RenderOverrides {
    std::optional<int> width, height, spp, depth, degree, light_samples, threads, frame;
    std::optional<double> cutoff, exposure;
    std::optional<std::string> sampler, engine, isa, accel, colorspace, tonemap;
};

/// Sets the override `name` from its text (the command line's spelling: "spp", "light_samples",
/// ...); false for a name that is not an override. UsageError for a bad value.
bool set_override(RenderOverrides& o, const std::string& name, const std::string& value);
/// The override names, comma-separated, for messages.
std::string override_names();

struct RenderJob {
    Scene scene;
    EngineKind engine = EngineKind::Stream;
    EngineOptions options;
    std::unique_ptr<StreamProfile> profile;  ///< when profiling (options.profile points to it)
    int threads = 0;                         ///< <= 0: all cores
};

/// Applies the overrides to the scene and checks them (UsageError: one line).
RenderJob build_render_job(Scene scene, const RenderOverrides& o, bool profile);

}  // namespace streamrt
