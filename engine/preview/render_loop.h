#pragma once
// The preview's renders (docs/preview.md): one background thread renders the scene as it
// stands, a quick pass first (a quarter of the size, one sample) then the render job the
// command line would run, and starts again, cancelling the render under way, whenever the
// scene, the camera or the settings change. Every pass goes through driver/render_job.h, so
// the full pass is the CLI's picture, bit for bit.
#include <glm/glm.hpp>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "driver/render_job.h"
#include "parallel/parallelism.h"
#include "scene/scene.h"

namespace streamrt::preview {

/// The camera the page moves: the scene's look-at keys.
struct ViewCamera {
    glm::dvec3 eye{0, 0, 5}, look{0, 0, 0}, up{0, 1, 0};
    double fov = 45;
};

/// The look-at keys of a scene's camera; an explicit-form camera (Md) is read back as the
/// look-at camera with the same eye, screen centre, up axis and vertical field of view.
ViewCamera view_of(const Camera& c, int width, int height);

/// `camera eye=... look=... up=... fov=...` (with the scene's aperture and focus when set):
/// the statement of docs/scene-format.md that gives this camera, numbers to 6 significant digits.
std::string camera_statement(const ViewCamera& v, const Camera& scene_camera);

/// What the page may change beside the camera; unset: the scene's own.
struct ViewSettings {
    std::optional<int> degree, spp;
    std::optional<std::string> engine;
};

/// One published picture.
struct Frame {
    std::uint64_t id = 0;  ///< 1, 2, ...: every picture published
    std::string png;       ///< the picture as the scene's PNG output would hold it
    int width = 0, height = 0, spp = 0;
    bool full = false;  ///< the full pass (the scene's settings), else a quick one
    double seconds = 0;
    std::uint64_t rays = 0;
    double rays_per_second = 0;
    std::optional<double> estimated_error;  ///< adaptive sampling's estimate, when adaptive
    /// Adaptive sampling's full pass: each pixel's sample count over the most any took, grey
    /// (the sample map of --aov samples=, as a picture); empty otherwise.
    std::string samples_png;
    /// The stream engine's full pass: its per-stage profile (the text of --profile).
    std::string profile;
};

/// What /status reports.
struct LoopStatus {
    std::uint64_t frame = 0;
    std::string pass;  ///< "quick", "full", or "idle" once the full pass is published
    int tiles_done = 0, tiles_total = 0;
    std::string error;  ///< the scene's or the settings' error, "" when there is none
    ViewCamera camera;
    std::string camera_statement;
    ViewSettings settings;
    int width = 0, height = 0, spp = 0, degree = 0;  ///< the full pass's
    std::string engine, output;
    std::string last_written;  ///< the file /render-full wrote last
};

class RenderLoop {
  public:
    /// `scene` as read; `jobs` worker threads (<= 0: all cores).
    RenderLoop(std::shared_ptr<const Scene> scene, int jobs);
    ~RenderLoop();
    void start();
    /// Cancels the render under way and joins the thread.
    void stop();

    /// A new version of the scene (the file saved): clears the error, keeps the page's camera.
    void set_scene(std::shared_ptr<const Scene> scene);
    /// The scene no longer reads (the last good picture stays): "file:line:col: message".
    void set_error(const std::string& error);
    /// The page moved the camera: while `moving`, quick passes only.
    void set_camera(const ViewCamera& camera, bool moving);
    /// Throws UsageError (nothing changed) for a value the render job refuses.
    void set_settings(const ViewSettings& settings);
    /// Renders the full-size picture and writes it to the scene's output (between passes, on
    /// the render thread); the file written. Throws what the render or the write threw.
    std::string render_full();

    std::shared_ptr<const Frame> frame() const;
    LoopStatus status() const;

  private:
    struct FullRequest {
        std::promise<std::string> done;
    };
    void run();
    /// The render job for the current state; `quick`: the reduced pass.
    RenderJob job_for(const std::shared_ptr<const Scene>& scene, const std::optional<ViewCamera>& camera,
                      const ViewSettings& settings, bool quick) const;
    /// Renders one pass; false when cancelled.
    bool render_pass(const RenderJob& job, bool full, std::uint64_t generation);

    int jobs_;
    Parallelism par_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::shared_ptr<const Scene> scene_;
    std::optional<ViewCamera> camera_;  ///< unset: the scene's own camera
    bool moving_ = false;
    ViewSettings settings_;
    std::string error_;
    std::string pass_ = "quick";
    std::string last_written_;
    std::uint64_t generation_ = 1, rendered_ = 0;  ///< state versions: wanted, rendered
    std::uint64_t next_frame_ = 1;
    std::shared_ptr<const Frame> frame_;
    std::shared_ptr<RenderProgress> progress_;
    std::unique_ptr<FullRequest> full_request_;
    std::atomic<bool> cancel_{false};  ///< the pass under way stops (RenderProgress::cancel)
    std::atomic<bool> stop_{false};    ///< the full-size render stops (only stop() sets it)
    bool stopping_ = false;
    std::thread thread_;
};

}  // namespace streamrt::preview
