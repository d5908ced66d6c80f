#pragma once
// The streamrt command (docs/scene-format.md; README "Using it"), one concept a file:
// command.cpp (options, dispatch, exit status; main.cpp is the program's main), job.cpp (the render job from the options and the
// checks before rendering), progress.h (the progress bar), picture.cpp (one picture, both
// engines, frames), tiled.cpp (shards, checkpoints, tile costs, MPI, merge).
#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "scene/scene_bvh.h"
#include "core/error.h"
#include "distributed/mpi_render.h"
#include "distributed/scene_bundle.h"
#include "distributed/tile_file.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "kernels/kernel_table.h"
#include "parallel/parallelism.h"
#include "driver/limits.h"
#include "driver/render.h"
#include "driver/render_job.h"
#include "scene/animation.h"
#include "scene/parser.h"

#ifndef STREAMRT_VERSION
#define STREAMRT_VERSION "dev"
#endif

namespace streamrt::cli {

namespace fs = std::filesystem;

/// Set by SIGINT/SIGTERM: the render stops, nothing is written (exit status 130). The one
/// process-wide flag: a signal handler can only reach a global.
extern std::atomic<bool> g_cancel;
struct Interrupted {};

struct Options {
    std::string scene_path;
    int jobs = 0;
    std::string output;
    std::optional<int> spp, width, height, degree, depth;
    std::optional<double> cutoff;
    std::optional<int> light_samples;
    std::string engine = "stream";
    std::string accel = "auto";
    std::string isa;
    bool profile = false;
    std::string profile_json;
    bool compare = false;
    std::string shade = "simd";
    std::optional<int> mesh_hybrid;
    std::string sampler;
    bool quiet = false;
    bool check_only = false;
    bool mpi = false;
    std::string mpi_schedule = "dynamic";
    std::string shard;
    int shard_k = -1, shard_n = 0;
    std::string checkpoint;
    bool resume = false;
    std::string tile_costs;
    // Display colour overrides of the image keys (docs/scene-format.md, "Output and display colour").
    std::string colorspace, tonemap;
    std::optional<double> exposure;
    std::string frames;  ///< --frames A..B (animation)
    // Adaptive sampling (docs/adaptive-sampling.md).
    std::optional<double> adaptive, target_error, time_limit;
    std::string aov;  ///< --aov samples=FILE: the per-pixel sample counts and error estimates
    std::string memory_limit;  ///< --memory-limit SIZE (core/memory_budget.h); empty: the available memory
    /// Rendered tile by tile (render_tiles) rather than as one image.
    bool tiled() const { return mpi || shard_n > 0 || !checkpoint.empty() || !tile_costs.empty(); }
};

/// A render ready to go (driver/render_job.h), and what the command line adds to it. The
/// scene is never changed: a frame is set here, its scene made when the engine is prepared
/// and its file name where the file is written (output_name).
struct Job : RenderJob {
    double read_seconds = 0;
    int frame = -1;         ///< the frame being rendered (animation; -1: a still picture)
    bool animated = false;  ///< the scene has keys (kept when the job lets go of the scene)
};

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// ---- animation: the frames to render (scene/animation.h) ----
struct FramePlan {
    int first = 0, last = 0;
    bool any = false;   ///< frames asked for (--frames or image frames=)
    bool many = false;  ///< more than one
};

// ---- job.cpp ----
/// Prints the error being handled (one line) and gives its exit status: 2 bad usage or bad
/// scene, 1 render or I/O failure, 130 interrupted. `quiet`: the status only.
int report_error(std::exception_ptr error, bool quiet = false);
/// This process's rank when an MPI launcher started it (0 otherwise).
int launcher_rank();
/// What named a file this run writes, for the messages that refuse it: an option ("-o",
/// "--checkpoint", "--aov samples=", ...) or, when `option` is empty, the scene's output=
/// (SceneError at its file:line:col; without one, the scene's default name).
struct NamedBy {
    std::string option;
    const Scene* scene = nullptr;
    /// Throws (exit status 2): "OPTION NAME: WHY", "file:line:col: output=NAME: WHY".
    [[noreturn]] void refuse(const std::string& name, const std::string& why) const;
};
/// Refuses, before rendering, an output in a missing or read-only folder, or a folder.
void check_writable_path(const std::string& out, const NamedBy& by);
/// The same, and an output whose extension names no image format.
void check_output_path(const std::string& out, const NamedBy& by);
/// Refuses (exit status 2) a file to be written that is one the scene read (Scene::inputs):
/// a UsageError naming `option` ("-o", "--checkpoint", ...), or with an empty option a
/// SceneError at the scene's `output=`. `pattern`: the frames' name it was made from, if any.
void check_not_input(const Scene& scene, const std::string& out, const std::string& option,
                     const std::string& pattern);
/// Applies the command line to a loaded scene and checks everything before rendering.
/// `writes`: this process writes the output (false on MPI ranks other than 0).
/// `check_isa`: --isa must be supported here (MPI ranks agree on it together instead).
Job make_job(const Options& opt, std::shared_ptr<const Scene> scene, bool writes, bool check_isa);
/// The engine's set-up for the job's frame. Unless `keep_scene` (more set-ups follow) or the
/// scene is animated, the job lets go of its scene: the stream engine renders from its own
/// tables, and the scene's objects are freed then (the recursive engine holds the scene).
std::unique_ptr<PreparedRender> prepare(Job& job, EngineKind which, bool keep_scene);
void report_profile(const Options& opt, const StreamProfile* profile);
/// The summary line.
void print_summary(const Options& opt, const Job& job, int jobs, const std::string& how, double seconds,
                   const RayCounts& counts, double setup_seconds, double write_seconds,
                   const std::optional<AdaptiveSummary>& adaptive = std::nullopt);
/// The file of --aov samples=FILE (empty: none); UsageError for another AOV or format.
std::string sample_map_path(const Options& opt);

// ---- picture.cpp ----
/// The output name of frame `frame` (printf-style %d), nullopt without one.
std::optional<std::string> frame_output_name(const std::string& pattern, int frame);
/// The file the job's picture goes to: the output name, for an animated scene with the
/// frame's number put in its %d (a still picture of an animated scene is frame 0).
std::string output_name(const Job& job);
FramePlan plan_frames(const Options& opt, const RenderSettings& s);
int render_picture(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle,
                   std::unique_ptr<PreparedRender>& prepared);
int render_frames(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const FramePlan& plan);

// ---- tiled.cpp ----
int render_tiled(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const MpiSession* mpi,
                 std::unique_ptr<PreparedRender>& prepared);
int run_mpi(const Options& opt, int argc, char** argv);
int run_merge(int argc, char** argv);

// ---- command.cpp ----
/// The whole command: `argv` as the program gets it (argv[0] its name); an error is reported
/// here (one line on stderr) and becomes the exit status. The program's main, and
/// `python -m streamrt` through the Python module.
int run_command(int argc, char** argv);

}  // namespace streamrt::cli
