// The preview's render thread (preview/render_loop.h).
#include "preview/render_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/error.h"
#include "driver/limits.h"
#include "image/image_io.h"

namespace streamrt::preview {

namespace {

/// The quick pass's size: a quarter of each side, so a frame costs about 1/16 of a full pass
/// at one sample, which keeps pictures coming while the camera moves.
constexpr int kQuickDivisor = 4;

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", std::abs(v) < 5e-7 ? 0.0 : v);  // no "-0" or 1e-17 in a statement
    return buf;
}

std::string vec(const glm::dvec3& v) { return number(v.x) + "," + number(v.y) + "," + number(v.z); }

}  // namespace

ViewCamera view_of(const Camera& c, int width, int height) {
    if (c.look_at) return ViewCamera{c.eye, c.look, c.up, c.fov};
    // Md maps the canonical eye (0,0,1) to the eye, the screen centre (0,0,0) to the point
    // looked at, and its y column is the screen's up axis, ry long at distance df.
    const glm::dmat4 m = c.world_from_canonical(width, height);
    ViewCamera v;
    v.eye = glm::dvec3(m * glm::dvec4(0, 0, 1, 1));
    v.look = glm::dvec3(m * glm::dvec4(0, 0, 0, 1));
    v.up = glm::normalize(glm::dvec3(m[1]));
    v.fov = 2.0 * std::atan(glm::length(glm::dvec3(m[1])) / glm::length(glm::dvec3(m[2]))) * 180.0 / std::numbers::pi;
    return v;
}

std::string camera_statement(const ViewCamera& v, const Camera& scene_camera) {
    std::string s = "camera eye=" + vec(v.eye) + " look=" + vec(v.look) + " up=" + vec(v.up) + " fov=" + number(v.fov);
    if (scene_camera.aperture > 0) s += " aperture=" + number(scene_camera.aperture);
    if (scene_camera.focus > 0) s += " focus=" + number(scene_camera.focus);
    return s;
}

RenderLoop::RenderLoop(std::shared_ptr<const Scene> scene, int jobs)
    : jobs_(jobs), par_(jobs), scene_(std::move(scene)) {}

RenderLoop::~RenderLoop() { stop(); }

void RenderLoop::start() {
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void RenderLoop::stop() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
        cancel_.store(true);
        stop_.store(true);
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void RenderLoop::set_scene(std::shared_ptr<const Scene> scene) {
    {
        std::lock_guard lock(mutex_);
        scene_ = std::move(scene);
        error_.clear();
        moving_ = false;
        ++generation_;
        cancel_.store(true);
    }
    wake_.notify_all();
}

void RenderLoop::set_error(const std::string& error) {
    // The picture under way is of the last good scene, which stays on the page: it goes on.
    std::lock_guard lock(mutex_);
    error_ = error;
}

void RenderLoop::set_camera(const ViewCamera& camera, bool moving) {
    {
        std::lock_guard lock(mutex_);
        camera_ = camera;
        moving_ = moving;
        ++generation_;
        cancel_.store(true);
    }
    wake_.notify_all();
}

void RenderLoop::set_settings(const ViewSettings& settings) {
    std::shared_ptr<const Scene> scene;
    std::optional<ViewCamera> camera;
    {
        std::lock_guard lock(mutex_);
        scene = scene_;
        camera = camera_;
    }
    (void)job_for(scene, camera, settings, false);  // refused here, before anything changes
    {
        std::lock_guard lock(mutex_);
        settings_ = settings;
        moving_ = false;
        ++generation_;
        cancel_.store(true);
    }
    wake_.notify_all();
}

std::string RenderLoop::render_full() {
    std::future<std::string> done;
    {
        std::lock_guard lock(mutex_);
        if (stopping_) throw RenderError("the preview is stopping");
        if (full_request_) throw UsageError("a full-size render is already under way");
        full_request_ = std::make_unique<FullRequest>();
        done = full_request_->done.get_future();
        cancel_.store(true);  // the pass under way makes room; it is rendered again after
    }
    wake_.notify_all();
    return done.get();
}

std::shared_ptr<const Frame> RenderLoop::frame() const {
    std::lock_guard lock(mutex_);
    return frame_;
}

LoopStatus RenderLoop::status() const {
    std::lock_guard lock(mutex_);
    LoopStatus s;
    s.frame = frame_ ? frame_->id : 0;
    s.pass = pass_;
    if (progress_) s.tiles_done = progress_->tiles_done.load(), s.tiles_total = progress_->tiles_total;
    s.error = error_;
    const RenderSettings& rs = scene_->settings;
    s.camera = camera_ ? *camera_ : view_of(scene_->camera, rs.width, rs.height);
    s.camera_statement = camera_statement(s.camera, scene_->camera);
    s.settings = settings_;
    s.width = rs.width, s.height = rs.height;
    s.spp = settings_.spp.value_or(rs.spp), s.degree = settings_.degree.value_or(rs.degree);
    s.engine = settings_.engine.value_or("stream");
    s.output = rs.output;
    s.last_written = last_written_;
    return s;
}

RenderJob RenderLoop::job_for(const std::shared_ptr<const Scene>& scene, const std::optional<ViewCamera>& camera,
                              const ViewSettings& settings, bool quick) const {
    std::shared_ptr<const Scene> viewed = scene;
    if (camera) {
        // A parsed scene is never changed (scene/scene.h): the moved camera is a copy's.
        auto copy = std::make_shared<Scene>(*scene);
        copy->camera.look_at = true;
        copy->camera.eye = camera->eye, copy->camera.look = camera->look, copy->camera.up = camera->up;
        copy->camera.fov = camera->fov;
        viewed = std::move(copy);
    }
    // The command line's own defaults (cli/cli.h's Options), so that the full pass is its job.
    RenderOverrides o;
    o.threads = jobs_;
    o.engine = settings.engine.value_or("stream");
    o.accel = "auto";
    o.shade = "simd";
    o.degree = settings.degree;
    o.spp = settings.spp;
    if (quick) {
        const RenderSettings& s = viewed->settings;
        o.width = std::max(1, s.width / kQuickDivisor);
        o.height = std::max(1, s.height / kQuickDivisor);
        o.spp = 1;
        o.adaptive = 0.0;  // one sample leaves nothing to adapt
    }
    // The full pass of the stream engine keeps its per-stage figures for the page's profile
    // view (counting them changes no pixel: the render job's test checks the CLI's bits).
    const bool profile = !quick && o.engine == std::string("stream");
    RenderJob job = build_render_job(std::move(viewed), o, profile);
    // As the command line does before rendering (cli/job.cpp): a render that cannot fit in
    // this machine is one line on the page (MemoryShortage), not an allocation failure.
    check_render_memory(*job.scene, job.render_settings, job.engine == EngineKind::Stream,
                        jobs_ > 0 ? jobs_ : default_jobs());
    return job;
}

bool RenderLoop::render_pass(const RenderJob& job, bool full, std::uint64_t generation) {
    auto progress = std::make_shared<RenderProgress>();
    progress->cancel = &cancel_;
    progress->tiles_total = tile_count(job.render_settings.width, job.render_settings.height);
    {
        std::lock_guard lock(mutex_);
        progress_ = progress;
        pass_ = full ? "full" : "quick";
    }
    auto prepared = prepare_job(job, job.engine, -1);
    const RenderResult r = render_prepared(*prepared, par_, progress.get());
    if (cancel_.load()) return false;
    auto frame = std::make_shared<Frame>();
    const RenderSettings& s = job.render_settings;
    const ByteSink sink = [&](std::span<const iovec> pieces) {
        for (const iovec& p : pieces) frame->png.append(static_cast<const char*>(p.iov_base), p.iov_len);
    };
    WriteOptions wo;
    wo.par = &par_;
    encode_image(r.image, image_format(".png"), display_of(s), sink, wo);
    frame->width = s.width, frame->height = s.height, frame->spp = s.spp, frame->full = full;
    frame->seconds = r.seconds;
    frame->rays = r.counts.total();
    frame->rays_per_second = double(frame->rays) / std::max(r.seconds, 1e-9);
    if (r.adaptive) frame->estimated_error = r.adaptive->estimated_rmse;
    if (r.adaptive && r.sample_map.width == s.width && r.sample_map.height == s.height) {
        // Channel 0 of the sample map is each pixel's sample count (driver/render.h).
        float most = 1.f;
        for (std::size_t i = 0; i < r.sample_map.rgb.size(); i += 3) most = std::max(most, r.sample_map.rgb[i]);
        Framebuffer grey(s.width, s.height);
        for (std::size_t i = 0; i < grey.rgb.size(); i += 3)
            grey.rgb[i] = grey.rgb[i + 1] = grey.rgb[i + 2] = r.sample_map.rgb[i] / most;
        const ByteSink grey_sink = [&](std::span<const iovec> pieces) {
            for (const iovec& p : pieces) frame->samples_png.append(static_cast<const char*>(p.iov_base), p.iov_len);
        };
        encode_image(grey, image_format(".png"), Display{}, grey_sink, wo);
    }
    if (job.profile) {
        job.profile->adaptive = r.adaptive;
        frame->profile = job.profile->text();
    }
    std::lock_guard lock(mutex_);
    if (generation != generation_) return false;  // the state moved on while encoding
    frame->id = next_frame_++;
    frame_ = std::move(frame);
    return true;
}

void RenderLoop::run() {
    for (;;) {
        std::unique_ptr<FullRequest> full_request;
        std::shared_ptr<const Scene> scene;
        std::optional<ViewCamera> camera;
        ViewSettings settings;
        bool moving = false;
        std::uint64_t generation = 0;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stopping_ || full_request_ || rendered_ != generation_; });
            if (stopping_) {
                if (full_request_)
                    full_request_->done.set_exception(std::make_exception_ptr(RenderError("the preview stopped")));
                return;
            }
            full_request = std::move(full_request_);
            scene = scene_, camera = camera_, settings = settings_, moving = moving_, generation = generation_;
            cancel_.store(false);
        }
        if (full_request) {
            // The command line's render of the same job, written where it writes.
            try {
                const RenderJob job = job_for(scene, camera, settings, false);
                auto prepared = prepare_job(job, job.engine, -1);
                // Not cancelled by a camera move or a save (the file asked for is written),
                // only by stop().
                RenderProgress progress;
                progress.cancel = &stop_;
                const RenderResult r = render_prepared(*prepared, par_, &progress);
                if (stop_.load()) throw RenderError("the preview stopped before the full-size picture was done");
                const RenderSettings& s = job.render_settings;
                if (const SceneInput* in = scene->input_at(s.output))
                    throw UsageError("output=" + s.output + ": is an input of the scene (" + in->describe() + ")");
                WriteOptions wo;
                wo.par = &par_;
                write_image(s.output, r.image, display_of(s), wo);
                {
                    std::lock_guard lock(mutex_);
                    last_written_ = s.output;
                }
                full_request->done.set_value(s.output);
            } catch (...) {
                full_request->done.set_exception(std::current_exception());
            }
            continue;
        }
        try {
            bool done = render_pass(job_for(scene, camera, settings, true), false, generation);
            if (done && !moving) done = render_pass(job_for(scene, camera, settings, false), true, generation);
            std::lock_guard lock(mutex_);
            if (done && generation == generation_) {
                rendered_ = generation;
                if (!moving) pass_ = "idle";
            }
        } catch (const std::exception& e) {
            // A render the settings cannot make (memory, a refused value): said on the page,
            // not rendered again until something changes.
            std::lock_guard lock(mutex_);
            error_ = e.what();
            if (generation == generation_) rendered_ = generation;
        }
    }
}

}  // namespace streamrt::preview
