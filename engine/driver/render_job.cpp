#include "driver/render_job.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <type_traits>
#include <functional>
#include <utility>

#include "core/error.h"
#include "kernels/kernel_table.h"
#include "scene/animation.h"
#include "scene/scene_bvh.h"

namespace streamrt {

namespace {

int to_int(const std::string& name, const std::string& v) {
    int out = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
    if (ec != std::errc() || end != v.data() + v.size()) throw UsageError(name + ": expected an integer, got '" + v + "'");
    return out;
}
double to_double(const std::string& name, const std::string& v) {
    try {
        std::size_t used = 0;
        const double d = std::stod(v, &used);
        if (used == v.size()) return d;
    } catch (const std::exception&) {
    }
    throw UsageError(name + ": expected a number, got '" + v + "'");
}
/// The value named v in the table, or a UsageError naming the choices.
template <class E, std::size_t N>
E named(const std::string& name, const std::string& v, const EnumName<E> (&names)[N]) {
    if (const std::optional<E> e = value_named(names, v)) return *e;
    throw UsageError(name + ": expected " + names_list(names) + ", got '" + v + "'");
}
template <class E, std::size_t N>
std::string one_of(const std::string& name, const std::string& v, const EnumName<E> (&names)[N]) {
    named(name, v, names);
    return v;
}

struct Field {
    const char* name;
    std::function<void(RenderOverrides&, const std::string&)> set;
};
const Field kFields[] = {
    {"width", [](RenderOverrides& o, const std::string& v) { o.width = to_int("width", v); }},
    {"height", [](RenderOverrides& o, const std::string& v) { o.height = to_int("height", v); }},
    {"spp", [](RenderOverrides& o, const std::string& v) { o.spp = to_int("spp", v); }},
    {"depth", [](RenderOverrides& o, const std::string& v) { o.depth = to_int("depth", v); }},
    {"degree", [](RenderOverrides& o, const std::string& v) { o.degree = to_int("degree", v); }},
    {"sampler", [](RenderOverrides& o, const std::string& v) { o.sampler = one_of("sampler", v, kSamplePatternNames); }},
    {"cutoff", [](RenderOverrides& o, const std::string& v) { o.cutoff = to_double("cutoff", v); }},
    {"light_samples", [](RenderOverrides& o, const std::string& v) { o.light_samples = to_int("light_samples", v); }},
    {"engine", [](RenderOverrides& o, const std::string& v) { o.engine = one_of("engine", v, kEngineNames); }},
    {"isa", [](RenderOverrides& o, const std::string& v) { o.isa = one_of("isa", v, kIsaNames); }},
    {"accel", [](RenderOverrides& o, const std::string& v) { o.accel = one_of("accel", v, accel::kAccelModeNames); }},
    {"threads", [](RenderOverrides& o, const std::string& v) { o.threads = to_int("threads", v); }},
    {"frame", [](RenderOverrides& o, const std::string& v) { o.frame = to_int("frame", v); }},
    {"colorspace", [](RenderOverrides& o, const std::string& v) { o.colorspace = one_of("colorspace", v, kColorSpaceNames); }},
    {"tonemap", [](RenderOverrides& o, const std::string& v) { o.tonemap = one_of("tonemap", v, kTonemapNames); }},
    {"exposure", [](RenderOverrides& o, const std::string& v) { o.exposure = to_double("exposure", v); }},
    {"shade", [](RenderOverrides& o, const std::string& v) { o.shade = one_of("shade", v, kShadeModeNames); }},
    {"mesh_hybrid", [](RenderOverrides& o, const std::string& v) { o.mesh_hybrid = to_int("mesh_hybrid", v); }},
    {"adaptive", [](RenderOverrides& o, const std::string& v) { o.adaptive = to_double("adaptive", v); }},
    {"target_error", [](RenderOverrides& o, const std::string& v) { o.target_error = to_double("target_error", v); }},
    {"time_limit", [](RenderOverrides& o, const std::string& v) { o.time_limit = to_double("time_limit", v); }},
};

// The token's spelling of each kind of field.
std::string token_value(int v) { return std::to_string(v); }
std::string token_value(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}
std::string token_value(SamplePattern v) { return std::string(name_of(kSamplePatternNames, v)); }
std::string token_value(Calibration v) { return std::string(name_of(kCalibrationNames, v)); }
std::string token_value(ColorSpace v) { return std::string(name_of(kColorSpaceNames, v)); }
std::string token_value(Tonemap v) { return std::string(name_of(kTonemapNames, v)); }
std::string token_value(ExrPixels v) { return std::string(name_of(kExrPixelsNames, v)); }
std::string token_value(EngineKind v) { return std::string(name_of(kEngineNames, v)); }
std::string token_value(Isa v) { return std::string(name_of(kIsaNames, v)); }
std::string token_value(accel::AccelMode v) { return std::string(name_of(accel::kAccelModeNames, v)); }
std::string token_value(ShadeMode v) { return std::string(name_of(kShadeModeNames, v)); }

}  // namespace

bool set_override(RenderOverrides& o, const std::string& name, const std::string& value) {
    for (const Field& f : kFields)
        if (name == f.name) {
            f.set(o, value);
            return true;
        }
    return false;
}

std::string override_names() {
    std::string s;
    for (const Field& f : kFields) s += (s.empty() ? "" : ", ") + std::string(f.name);
    return s;
}

std::string settings_token(const PixelSettings& s) {
    std::string token = "pixels=" + std::to_string(kPixelsRevision);
    s.for_each_field([&](const char* name, const auto& value) {
        if (!token.empty()) token += ',';
        token += name;
        token += '=';
        // The recursive engine has no kernels: its pixels do not depend on the level.
        if constexpr (std::is_same_v<std::decay_t<decltype(value)>, Isa>)
            token += s.engine == EngineKind::Stream ? token_value(value) : "none";
        else
            token += token_value(value);
    });
    return token;
}

RenderJob build_render_job(std::shared_ptr<const Scene> scene, const RenderOverrides& o, bool profile) {
    RenderJob job;
    job.scene = std::move(scene);
    job.render_settings = job.scene->settings;
    RenderSettings& s = job.render_settings;
    const auto in = [](const char* name, int v, int lo, int hi) {
        if (v < lo || v > hi)
            throw UsageError(std::string(name) + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                             "], got " + std::to_string(v));
        return v;
    };
    if (o.width) s.width = in("width", *o.width, 1, 32768);
    if (o.height) s.height = in("height", *o.height, 1, 32768);
    if (o.spp) s.spp = in("spp", *o.spp, 1, 65536);
    if (o.depth) s.depth = in("depth", *o.depth, 0, 256);
    if (o.degree) s.degree = in("degree", *o.degree, 0, 6);
    if (o.cutoff) {
        if (!(*o.cutoff >= 0 && *o.cutoff <= 1)) throw UsageError("cutoff must be in [0, 1]");
        s.cutoff = *o.cutoff;
    }
    if (o.adaptive) {
        if (!(*o.adaptive >= 0 && *o.adaptive <= 1)) throw UsageError("adaptive must be in [0, 1]");
        s.adaptive = *o.adaptive;
    }
    if (o.target_error) {
        if (!(*o.target_error > 0 && *o.target_error <= 1)) throw UsageError("target_error must be in (0, 1]");
        job.options.adaptive_stop.target_error = *o.target_error;
        if (s.adaptive == 0) s.adaptive = *o.target_error;  // no pixel need be finer than the image's target
    }
    if (o.time_limit) {
        if (!(*o.time_limit > 0 && std::isfinite(*o.time_limit))) throw UsageError("time_limit must be a number of seconds > 0");
        if (s.adaptive == 0) throw UsageError("time_limit stops adaptive sampling: it needs adaptive or target_error");
        job.options.adaptive_stop.time_limit = *o.time_limit;
    }
    if (o.light_samples) s.light_samples = in("light_samples", *o.light_samples, 1, 4096);  // rendered_light
    if (o.sampler) s.pattern = named("sampler", *o.sampler, kSamplePatternNames);
    if (o.colorspace) s.colorspace = named("colorspace", *o.colorspace, kColorSpaceNames);
    if (o.tonemap) s.tonemap = named("tonemap", *o.tonemap, kTonemapNames);
    if (o.output) s.output = *o.output;
    if (o.exposure) s.exposure = *o.exposure;
    // The frame's scene is made when the engine is prepared (prepare_job).
    if (o.frame && *o.frame < 0) throw UsageError("frame must be >= 0");
    if (s.adaptive > 0) {
        // spp is the most a pixel takes. Given with the request, it is kept; a scene that asks
        // for adaptive sampling itself (image adaptive=) names its cap with its spp. Otherwise
        // the scene's spp is a uniform count: as a cap it cut a request short without a word
        // (whitted.cfg's spp=4 stopped --target-error 0.005 at an estimated 0.0203), so the
        // cap is then at least kDefaultAdaptiveCap, as it is for a scene's one sample, which
        // would leave nothing to adapt.
        const bool scene_asks = job.scene->settings.adaptive > 0;
        if (o.spp) {
            job.adaptive_cap_from = AdaptiveCapFrom::Given;
        } else if ((s.spp == 1 || !scene_asks) && s.spp < kDefaultAdaptiveCap) {
            s.spp = kDefaultAdaptiveCap;
            job.adaptive_cap_from = AdaptiveCapFrom::Default;
        }
        if (s.spp < 2) throw UsageError("adaptive sampling needs spp >= 2, the most samples a pixel may take");
        if (s.pattern == SamplePattern::Grid)
            throw UsageError("adaptive sampling needs sampler stratified or random (grid puts every round's samples "
                             "on the same points)");
    }
    job.engine = o.engine ? named("engine", *o.engine, kEngineNames) : EngineKind::Stream;
    job.threads = o.threads.value_or(0);
    if (o.accel) job.options.accel.mode = named("accel", *o.accel, accel::kAccelModeNames);
    if (o.isa) {
        parse_isa(*o.isa, job.options.isa);
        if (!isa_supported(job.options.isa)) throw UsageError("isa " + *o.isa + ": this CPU does not support it");
    }
    if (o.shade) job.options.shade = named("shade", *o.shade, kShadeModeNames);
    if (o.mesh_hybrid) {
        if (*o.mesh_hybrid < 0 || *o.mesh_hybrid > 64) throw UsageError("mesh_hybrid must be in [0, 64]");
        job.options.accel.mesh_hybrid_lanes = std::uint32_t(*o.mesh_hybrid);
    }
    if (profile) {
        job.profile = std::make_unique<StreamProfile>();
        job.options.profile = job.profile.get();
    }
    PixelSettings& p = job.settings;
    p.width = s.width, p.height = s.height, p.spp = s.spp, p.depth = s.depth, p.degree = s.degree;
    p.light_samples = o.light_samples.value_or(0);
    p.frame = o.frame.value_or(-1);
    p.cutoff = s.cutoff, p.exposure = s.exposure;
    p.adaptive = s.adaptive, p.target_error = job.options.adaptive_stop.target_error;
    p.sampler = s.pattern, p.calibration = s.calibration, p.colorspace = s.colorspace, p.tonemap = s.tonemap;
    p.exr = s.exr;
    p.engine = job.engine, p.isa = job.options.isa, p.accel = job.options.accel.mode, p.shade = job.options.shade;
    p.mesh_hybrid = int(job.options.accel.mesh_hybrid_lanes);
    return job;
}

std::unique_ptr<PreparedRender> prepare_job(const RenderJob& job, EngineKind engine, int frame) {
    return prepare_render(scene_at_frame(job.scene, frame), job.render_settings, engine, job.options);
}

void update_job_frame(PreparedRender& prepared, const RenderJob& job, int from, int to) {
    // Without keys every frame is the scene as read (which a job may have let go of then).
    if (!job.scene || !job.scene->animation) return;
    prepared.update(scene_at_frame(job.scene, to), frame_change(*job.scene->animation, from, to));
}

}  // namespace streamrt
