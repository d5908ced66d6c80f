// streamrt: renders a .cfg scene (docs/scene-format.md) with the stream or the recursive engine.
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

namespace {

using namespace streamrt;
namespace fs = std::filesystem;

std::atomic<bool> g_cancel{false};
struct Interrupted {};
extern "C" void on_sigint(int) { g_cancel.store(true); }

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
    /// Rendered tile by tile (render_tiles) rather than as one image.
    bool tiled() const { return mpi || shard_n > 0 || !checkpoint.empty() || !tile_costs.empty(); }
};

std::optional<std::string> frame_output_name(const std::string& pattern, int frame);  // animation, below

/// This process's rank when an MPI launcher started it (0 otherwise): messages that every
/// rank would print alike are printed by rank 0 only.
int launcher_rank() {
    for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const char* r = std::getenv(v)) return std::atoi(r);
    return 0;
}

// A missing folder, a read-only folder or the scene file itself are refused before any
// rendering starts.
void check_writable_path(const std::string& out, const std::string& scene_path) {
    std::error_code ec;
    const fs::path target = fs::absolute(out, ec);
    if (fs::exists(scene_path, ec) && fs::exists(target, ec) && fs::equivalent(target, scene_path, ec))
        throw UsageError("output '" + out + "' is the scene file itself");
    if (fs::is_directory(target, ec)) throw UsageError("output '" + out + "' is a folder");
    const fs::path dir = target.parent_path();
    if (!fs::is_directory(dir, ec)) throw UsageError("output folder '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) throw UsageError("output folder '" + dir.string() + "' is not writable");
    // access() says yes to root everywhere; creating a file is what matters (read-only file
    // systems, /proc, ...). The probe is an unnamed file (O_TMPFILE): a process killed at any
    // moment leaves nothing in the folder. File systems without O_TMPFILE get a named probe,
    // removed at once.
    int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY, 0600);
    if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
        const fs::path probe = dir / ("." + target.filename().string() + ".probe" + std::to_string(::getpid()));
        fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
        if (fd >= 0) ::unlink(probe.c_str());
    }
    if (fd < 0)
        throw UsageError("output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    ::close(fd);
}

void check_output_path(const std::string& out, const std::string& scene_path) {
    if (!image_format_for(out))
        throw UsageError("output '" + out + "': unknown image format (expected " + image_format_extensions() + ")");
    check_writable_path(out, scene_path);
}

std::string format_seconds(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
    else std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    return buf;
}

// Progress bar with elapsed time and ETA, on stderr, only when stderr is a terminal.
class ProgressDisplay {
  public:
    ProgressDisplay(const RenderProgress& p, bool enabled) : p_(p), enabled_(enabled) {
        if (enabled_) thread_ = std::thread([this] { loop(); });
    }
    ~ProgressDisplay() { stop(); }
    void stop() {
        if (!enabled_) return;
        done_ = true;
        thread_.join();
        std::fprintf(stderr, "\r\033[K");
        enabled_ = false;
    }

  private:
    void loop() {
        const auto start = std::chrono::steady_clock::now();
        while (!done_) {
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const int done = p_.tiles_done.load(), total = std::max(1, p_.tiles_total);
            const double frac = double(done) / total;
            const int width = 30, filled = int(frac * width);
            std::string bar(std::size_t(filled), '#');
            bar.resize(std::size_t(width), '.');
            const std::string eta = frac > 0 ? format_seconds(elapsed * (1 - frac) / frac) : "?";
            std::fprintf(stderr, "\r[%s] %3d%%  elapsed %s  eta %s", bar.c_str(), int(frac * 100),
                         format_seconds(elapsed).c_str(), eta.c_str());
            std::fflush(stderr);
        }
    }
    const RenderProgress& p_;
    bool enabled_;
    std::atomic<bool> done_{false};
    std::thread thread_;
};

/// Prints the error being handled (one line) and gives its exit status: 2 bad usage or bad
/// scene, 1 render or I/O failure, 130 interrupted. `quiet`: the status only.
int report_error(std::exception_ptr error, bool quiet = false) {
    const auto say = [&](const std::string& text) {
        if (!quiet) std::fprintf(stderr, "streamrt: %s\n", text.c_str());
    };
    try {
        std::rethrow_exception(error);
    } catch (const Interrupted&) {
        say("interrupted, no image written");
        return 130;
    } catch (const SceneError& e) {
        say(e.what());
        return 2;
    } catch (const UsageError& e) {
        say(e.what());
        return 2;
    } catch (const RenderError& e) {
        say(e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        say("out of memory");
        return 1;
    } catch (const std::exception& e) {
        say(e.what());
        return 1;
    }
}

/// A render ready to go: the scene with the command line's settings, the engine's options.
struct Job {
    Scene scene;
    PixelSettings settings;  ///< everything the pixels depend on beside the scene's files
    EngineKind engine = EngineKind::Stream;
    EngineOptions eo;
    std::unique_ptr<StreamProfile> profile;  ///< when profiling (eo.profile points to it)
    double read_seconds = 0;
    int frame = -1;  ///< the frame being rendered (animation; -1: a still picture)
};

/// The command line's overrides of the scene's settings (driver/render_job.h: the Python
/// module builds its jobs from the same record).
RenderOverrides overrides_of(const Options& opt) {
    RenderOverrides o;
    o.width = opt.width, o.height = opt.height, o.spp = opt.spp, o.depth = opt.depth, o.degree = opt.degree;
    o.cutoff = opt.cutoff, o.light_samples = opt.light_samples, o.exposure = opt.exposure;
    const auto text = [](const std::string& v) { return v.empty() ? std::nullopt : std::optional<std::string>(v); };
    o.sampler = text(opt.sampler), o.colorspace = text(opt.colorspace), o.tonemap = text(opt.tonemap);
    o.engine = opt.engine, o.accel = opt.accel, o.shade = opt.shade;
    o.threads = opt.jobs;
    return o;
}

/// Applies the command line to a loaded scene and checks everything before rendering.
/// `writes`: this process writes the output (false on MPI ranks other than 0).
/// `check_isa`: --isa must be supported here (MPI ranks agree on it together instead).
Job make_job(const Options& opt, Scene scene, bool writes, bool check_isa) {
    if (!opt.isa.empty() && opt.engine == "recursive" && !opt.compare)
        throw UsageError("--isa chooses the stream engine's kernels; the recursive engine has none (scalar, double)");
    if ((opt.profile || !opt.profile_json.empty()) && opt.engine != "stream" && !opt.compare)
        throw UsageError("--profile needs the stream engine");
    RenderOverrides overrides = overrides_of(opt);
    if (check_isa && !opt.isa.empty()) overrides.isa = opt.isa;  // checked against this CPU there
    RenderJob built = build_render_job(std::move(scene), overrides, opt.profile || !opt.profile_json.empty());
    Job job;
    job.scene = std::move(built.scene);
    job.settings = built.settings;
    job.engine = built.engine;
    job.eo = built.options;
    job.profile = std::move(built.profile);
    if (!check_isa && !opt.isa.empty()) parse_isa(opt.isa, job.eo.isa);  // MPI: the ranks agree on it later
    job.settings.isa = job.eo.isa;
    RenderSettings& s = job.scene.settings;
    if (!opt.output.empty()) s.output = opt.output;
    if (opt.mpi && s.frames_last > s.frames_first)
        throw UsageError("--mpi renders one picture, the scene's image frames= asks for several (render them as a job "
                         "array, docs/distributed.md)");
    if (writes) {
        // A shard part is a tile file (docs/distributed.md), whatever its name.
        if (opt.shard_n > 0) check_writable_path(s.output, opt.scene_path);
        else check_output_path(s.output, opt.scene_path);
        if (!opt.profile_json.empty()) check_writable_path(opt.profile_json, opt.scene_path);
        if (!opt.tile_costs.empty()) check_writable_path(opt.tile_costs, opt.scene_path);
    }
    // Refuse, before allocating anything big, a render that cannot fit in this machine.
    const int jobs = opt.jobs > 0 ? opt.jobs : default_jobs();
    check_render_memory(job.scene, job.engine == EngineKind::Stream || opt.compare, jobs);
    return job;
}

/// The engine's set-up; the scene's object records are released when the engine renders
/// from its own tables (128 bytes each; 128 MB at 1e6 objects).
std::unique_ptr<PreparedRender> prepare(Job& job, EngineKind which, bool keep_objects) {
    auto prepared = prepare_render(job.scene, which, job.eo);
    // An animated scene keeps them: the next frames are set on them (scene/animation.h).
    if (!prepared->reads_scene_objects() && !keep_objects && !job.scene.animation) {
        std::vector<Object>().swap(job.scene.objects);
        std::vector<ObjectLoc>().swap(job.scene.object_locs);
    }
    return prepared;
}

void report_profile(const Options& opt, const StreamProfile* profile) {
    if (!profile) return;
    if (opt.profile) std::printf("%s", profile->text().c_str());
    if (!opt.profile_json.empty()) write_text_file(opt.profile_json, profile->json());
}

/// The summary line.
void print_summary(const Options& opt, const Job& job, int jobs, const std::string& how, double seconds,
                   const RayCounts& counts, double setup_seconds, double write_seconds) {
    if (opt.quiet) return;
    const RenderSettings& s = job.scene.settings;
    const std::string frame = job.frame >= 0 ? ", frame " + std::to_string(job.frame) : "";
    const double mrays = counts.total() / std::max(seconds, 1e-9) / 1e6;
    std::printf("%s: %dx%d, spp %d, degree %d, %s engine%s, -j%d: %.3f s, %llu rays (%.2f Mrays/s), set-up %.3f s -> %s"
                " (read %.3f s, set-up %.3f s, render %.3f s, write %.3f s)\n",
                opt.scene_path.c_str(), s.width, s.height, s.spp, s.degree, engine_name(job.engine), (how + frame).c_str(), jobs,
                seconds, static_cast<unsigned long long>(counts.total()), mrays, setup_seconds, s.output.c_str(),
                job.read_seconds, setup_seconds, seconds, write_seconds);
}

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Renders tile by tile: shards, checkpoints, tile costs, and MPI (`mpi` set). On MPI ranks
/// other than 0, renders what rank 0 hands out and returns.
/// `prepared`: the engine's set-up, kept from frame to frame (animation); made when null.
int render_tiled(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const MpiSession* mpi,
                 std::unique_ptr<PreparedRender>& prepared) {
    const RenderSettings& s = job.scene.settings;
    const bool rank0 = !mpi || mpi->rank() == 0;
    if (!prepared) prepared = prepare(job, job.engine, false);
    RenderProgress progress;
    progress.cancel = &g_cancel;
    const MpiSchedule schedule = opt.mpi_schedule == "static" ? MpiSchedule::Static : MpiSchedule::Dynamic;
    if (!rank0) {
        mpi_render_tiles(*mpi, *prepared, par, {}, schedule, [](const TileOutput&) {}, progress, job.profile.get());
        if (g_cancel.load()) throw Interrupted{};
        return 0;
    }
    TileFileHeader header;
    header.scene = bundle.content_hash();
    PixelSettings settings = job.settings;
    settings.isa = job.eo.isa;  // MPI: the level the ranks agreed on
    settings.frame = job.frame;  // parts of one frame only
    header.settings = settings_token(settings);
    header.width = s.width;
    header.height = s.height;
    header.tiles = tile_count(s.width, s.height);
    header.shard = opt.shard_n > 0 ? opt.shard_k : -1;
    header.shards = opt.shard_n;
    TileAssembly assembly(s.width, s.height);
    std::optional<TileJournal> journal;
    if (!opt.checkpoint.empty()) journal.emplace(opt.checkpoint, header, opt.resume, assembly);
    const std::vector<int> mine = opt.shard_n > 0 ? shard_tiles(header.tiles, opt.shard_k, opt.shard_n)
                                                  : shard_tiles(header.tiles, 0, 1);
    std::vector<int> todo;
    for (const int i : mine)
        if (!assembly.has(i)) todo.push_back(i);
    progress.tiles_total = int(mine.size());
    progress.tiles_done = int(mine.size() - todo.size());
    const TileSink sink = [&](const TileOutput& t) {
        if (assembly.place(t) && journal) journal->append(t);
    };
    std::vector<RankStats> ranks;
    const auto start = Clock::now();
    {
        ProgressDisplay display(progress, !opt.quiet && ::isatty(2));
        if (mpi) ranks = mpi_render_tiles(*mpi, *prepared, par, todo, schedule, sink, progress, job.profile.get());
        else render_tiles(*prepared, par, std::span<const int>(todo), sink, &progress);
    }
    const double seconds = since(start);
    if (g_cancel.load()) throw Interrupted{};  // the journal keeps what is done
    if (journal) journal->sync();
    const auto write_start = Clock::now();
    if (opt.shard_n > 0) {
        write_text_file(s.output, header.line() + "\n" + assembly.records(mine));
    } else {
        WriteOptions wo;
        wo.par = &par;
        wo.cancel = &g_cancel;
        if (!write_image(s.output, assembly.image(), display_of(s), wo)) throw Interrupted{};
    }
    const double write_seconds = since(write_start);
    if (!opt.tile_costs.empty()) write_text_file(opt.tile_costs, assembly.costs_csv());
    if (journal) journal->remove();
    if (job.profile && mpi) job.profile->threads = par.jobs();
    report_profile(opt, job.profile.get());
    if (opt.profile && mpi) std::printf("%s", rank_stats_text(ranks).c_str());
    std::string how = job.engine == EngineKind::Stream ? std::string(", isa ") + isa_name(job.eo.isa) : "";
    if (mpi)
        how += ", " + std::to_string(mpi->size()) + (mpi->size() == 1 ? " rank" : " ranks") + " (" +
               opt.mpi_schedule + ")";
    if (opt.shard_n > 0) how += ", shard " + opt.shard;
    if (journal && journal->resumed() > 0) how += ", " + std::to_string(journal->resumed()) + " tiles resumed";
    print_summary(opt, job, par.jobs(), how, seconds, assembly.counts(), prepared->setup_seconds, write_seconds);
    return 0;
}

/// streamrt --mpi: rank 0 reads and checks the scene and tells everyone; the others read
/// rank 0's copy; all agree on one kernel level, then render together.
int run_mpi(const Options& opt, int argc, char** argv) {
    MpiSession mpi(argc, argv);
    const bool rank0 = mpi.rank() == 0;
    SceneBundle bundle;
    std::optional<Job> job;
    int status = 0;
    if (rank0) {
        try {
            const auto start = Clock::now();
            Scene scene = load_scene_bundled(opt.scene_path, opt.jobs, bundle);
            const double read_seconds = since(start);
            job.emplace(make_job(opt, std::move(scene), true, false));
            job->read_seconds = read_seconds;
        } catch (...) {
            status = report_error(std::current_exception());
        }
    }
    if ((status = mpi.broadcast_status(status)) != 0) return status;
    mpi.broadcast_bundle(bundle);
    try {
        if (!rank0) {
            const auto start = Clock::now();
            job.emplace(make_job(opt, load_scene_from_bundle(bundle, opt.jobs), false, false));
            job->read_seconds = since(start);
        }
        // An animated scene: every rank renders its one frame, image frames=F or frame 0
        // (several frames are refused by make_job, --frames by run()).
        if (RenderSettings& rs = job->scene.settings; job->scene.animation || rs.has_frames()) {
            job->frame = rs.has_frames() ? rs.frames_first : 0;
            set_frame(job->scene, job->frame);
            rs.output = frame_output_name(rs.output, job->frame).value_or(rs.output);
        }
        // One kernel level for all: the one asked for if every rank has it, else the best
        // every rank has (float results differ in the last bits between levels).
        if (job->engine == EngineKind::Stream) {
            if (!opt.isa.empty()) {
                if (mpi.min_over_ranks(isa_supported(job->eo.isa) ? 1 : 0) == 0) {
                    if (rank0) std::fprintf(stderr, "streamrt: --isa %s: not every rank's CPU supports it\n", opt.isa.c_str());
                    return 2;
                }
            } else {
                job->eo.isa = Isa(mpi.min_over_ranks(int(best_isa())));
            }
        }
        if (opt.check_only) {
            if (rank0 && !opt.quiet)
                std::printf("%s: ok (%zu objects, %zu lights, %d ranks)\n", opt.scene_path.c_str(),
                            job->scene.objects.size(), job->scene.lights.size(), mpi.size());
            return 0;
        }
        Parallelism par(opt.jobs);
        std::unique_ptr<PreparedRender> prepared;
        return render_tiled(opt, *job, par, bundle, &mpi, prepared);
    } catch (const Interrupted&) {
        // Every rank was told to stop and has returned: the job ends together, no image.
        if (rank0) std::fprintf(stderr, "streamrt: interrupted, no image written\n");
        return 130;
    } catch (...) {
        // Past the common start, a failure on one rank ends the job.
        const std::exception_ptr error = std::current_exception();
        const int code = report_error(error, true);
        try {
            std::rethrow_exception(error);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "streamrt: rank %d: %s\n", mpi.rank(), e.what());
        } catch (...) {
            std::fprintf(stderr, "streamrt: rank %d: failed\n", mpi.rank());
        }
        mpi.abort(code);
    }
}

/// streamrt merge PART... -o OUT: the image from shard parts.
int run_merge(int argc, char** argv) {
    CLI::App app{"streamrt merge: puts the parts of a sharded render (streamrt --shard K/N) together", "streamrt merge"};
    std::vector<std::string> parts;
    std::string output;
    bool quiet = false;
    app.add_option("parts", parts, "The parts (all N of them)")->required();
    app.add_option("-o,--output", output, "Output image (.ppm, .png, .pfm or .exr)")->required();
    app.add_flag("-q,--quiet", quiet, "No summary line");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::fprintf(stderr, "streamrt merge: %s (see --help)\n", e.what());
        return 2;
    }
    check_output_path(output, "");
    TileFileHeader header;
    const Framebuffer image = merge_parts(parts, header);
    RenderSettings display;
    apply_display_settings(header, display);
    Parallelism par(0);
    WriteOptions wo;
    wo.par = &par;
    if (!write_image(output, image, display_of(display), wo)) throw Interrupted{};
    if (!quiet)
        std::printf("merged %zu parts (%dx%d, %d tiles, scene %s) -> %s\n", parts.size(), header.width, header.height,
                    header.tiles, header.scene.c_str(), output.c_str());
    return 0;
}

// ---- animation: the frames to render (scene/animation.h) ----
struct FramePlan {
    int first = 0, last = 0;
    bool any = false;   ///< frames asked for (--frames or image frames=)
    bool many = false;  ///< more than one
};

/// The output name of frame `frame`: the name's one printf-style %d (flags: 0 and a width,
/// e.g. %04d) replaced by the number, %% by %; nullopt when the name has no %d (or another
/// conversion, or two).
std::optional<std::string> frame_output_name(const std::string& pattern, int frame) {
    std::string out;
    bool found = false;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern[i] != '%') {
            out += pattern[i];
            continue;
        }
        if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
            out += '%';
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        const bool zero = j < pattern.size() && pattern[j] == '0';
        if (zero) ++j;
        std::size_t width = 0;
        while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9' && width < 64)
            width = width * 10 + std::size_t(pattern[j++] - '0');
        if (found || j >= pattern.size() || pattern[j] != 'd') return std::nullopt;
        std::string number = std::to_string(frame);
        if (number.size() < width) number.insert(0, width - number.size(), zero ? '0' : ' ');
        out += number;
        found = true;
        i = j;
    }
    if (!found) return std::nullopt;
    return out;
}

FramePlan plan_frames(const Options& opt, const RenderSettings& s) {
    FramePlan p;
    if (!opt.frames.empty()) {
        std::string why;
        if (!parse_frame_range(opt.frames, p.first, p.last, why)) throw UsageError("--frames " + opt.frames + ": " + why);
        p.any = true;
    } else if (s.has_frames()) {
        p.first = s.frames_first;
        p.last = s.frames_last;
        p.any = true;
    }
    p.many = p.last > p.first;
    if (p.many && !frame_output_name(s.output, p.first))
        throw UsageError("output '" + s.output +
                         "': several frames need one printf-style frame number in the name, e.g. out_%04d.png");
    if (p.many && (!opt.checkpoint.empty() || !opt.tile_costs.empty()))
        throw UsageError("--checkpoint and --tile-costs follow one picture: not with several frames");
    return p;
}

int render_picture(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle,
                   std::unique_ptr<PreparedRender>& prepared);
int render_frames(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const FramePlan& plan);

int run(int argc, char** argv) {
    if (argc >= 2 && std::string(argv[1]) == "merge") return run_merge(argc - 1, argv + 1);
    Options opt;
    CLI::App app{"streamrt: a SIMD ray-stream ray tracer for .cfg scenes (see docs/scene-format.md)", "streamrt"};
    app.footer("Also: streamrt merge PART... -o OUT (the parts of --shard renders)");
    app.add_option("scene", opt.scene_path, "Scene file (.cfg)")->required();
    app.add_option("-j,--jobs", opt.jobs, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
    app.add_option("-o,--output", opt.output, "Output image (.ppm, .png, .pfm or .exr); overrides the scene's");
    app.add_option("--spp", opt.spp, "Samples per pixel")->check(CLI::Range(1, 65536));
    app.add_option("--width", opt.width, "Image width in pixels")->check(CLI::Range(1, 32768));
    app.add_option("--height", opt.height, "Image height in pixels")->check(CLI::Range(1, 32768));
    app.add_option("--degree", opt.degree, "Shading degree 0..5 (handout)")->check(CLI::Range(0, 5));
    app.add_option("--depth", opt.depth, "Maximum bounces")->check(CLI::Range(0, 256));
    app.add_option("--cutoff", opt.cutoff,
                   "Weight cut-off: reflected and refracted rays worth less than this in every channel are not "
                   "traced (default 0: all; overrides the scene's image cutoff=)")
        ->check(CLI::Range(0.0, 1.0));
    app.add_option("--light-samples", opt.light_samples,
                   "Shadow rays per shaded point of every area light (overrides the lights' samples=)")
        ->check(CLI::Range(1, 4096));
    app.add_option("--engine", opt.engine, "Renderer: stream (SIMD ray streams) or recursive (the handout's baseline)")
        ->check(CLI::IsMember({"stream", "recursive"}));
    app.add_option("--isa", opt.isa, "Force the stream kernels' level: sse2, sse4.2, avx2 or avx512 (default: best the CPU has)")
        ->check(CLI::IsMember({"sse2", "sse4.2", "avx2", "avx512"}));
    app.add_option("--accel", opt.accel,
                   "Object hierarchy: auto (the BVH above a measured object count), bvh (always) or flat (the "
                   "handout's loop over all objects)")
        ->check(CLI::IsMember({"auto", "bvh", "flat"}));
    app.add_flag("--profile", opt.profile, "Print per-stage throughput of the stream engine");
    app.add_option("--profile-json", opt.profile_json, "Write the profile as JSON to FILE (also: --profile=json FILE)");
    app.add_option("--shade", opt.shade,
                   "Stream shade stage: simd (default: hits regrouped by object up to 8192 objects, by material and "
                   "kind above), sorted, gathered or scalar (for measurement)")
        ->check(CLI::IsMember({"simd", "sorted", "gathered", "scalar"}))
        ->group("");  // a measuring switch (docs/performance.md), not in the user's --help
    app.add_option("--colorspace", opt.colorspace, "8-bit output encoding: srgb (default) or linear (the handout's)")
        ->check(CLI::IsMember({"srgb", "linear"}));
    app.add_option("--tonemap", opt.tonemap, "Tone curve before calibration: clamp (default) or reinhard")
        ->check(CLI::IsMember({"clamp", "reinhard"}));
    app.add_option("--exposure", opt.exposure, "Multiplier of the linear values before the tone curve")
        ->check(CLI::Range(1e-6, 1e6));
    app.add_flag("--compare", opt.compare, "Render with both engines and report times, speedup and image difference");
    app.add_option("--sampler", opt.sampler, "Pixel sampling: stratified, grid or random")
        ->check(CLI::IsMember({"stratified", "grid", "random"}));
    app.add_flag("-q,--quiet", opt.quiet, "No progress bar and no summary line");
    app.add_flag("--check", opt.check_only, "Validate the scene and the output path, render nothing");
    app.add_flag("--mpi", opt.mpi, "Render with the ranks of an MPI job: mpirun -np N streamrt --mpi ...");
    app.add_option("--mpi-schedule", opt.mpi_schedule,
                   "How rank 0 hands out tiles: dynamic (chunks to whoever asks, default) or static (interleaved)")
        ->check(CLI::IsMember({"dynamic", "static"}));
    app.add_option("--shard", opt.shard,
                   "Render the K-th (from 0) of N interleaved tile sets into a part file; see 'streamrt merge'");
    app.add_option("--checkpoint", opt.checkpoint, "Journal finished tiles to FILE (removed once the image is written)");
    app.add_flag("--resume", opt.resume, "Continue the render journaled in --checkpoint FILE");
    app.add_option("--tile-costs", opt.tile_costs, "Write each tile's rays and seconds to FILE (CSV)");
    app.add_option("--frames", opt.frames,
                   "Render frames A..B of an animated scene (overrides image frames=), each to the output name's "
                   "printf-style %d: -o out_%04d.png");
    app.set_version_flag("--version", std::string("streamrt ") + STREAMRT_VERSION);
    // "--profile=json FILE" is the documented spelling; CLI11 sees it as --profile-json FILE.
    std::vector<std::string> args;
    for (int i = argc - 1; i >= 1; --i) args.emplace_back(argv[i]);  // CLI11 wants them reversed
    for (std::size_t i = 0; i < args.size(); ++i)
        if (args[i] == "--profile=json") args[i] = "--profile-json";
        else if (args[i] == "--profile=text") args[i] = "--profile";
    try {
        app.parse(args);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        // One line, like every other error (CLI11's own report adds a second line); under
        // an MPI launcher, from rank 0 only.
        if (launcher_rank() == 0) std::fprintf(stderr, "streamrt: %s (see --help)\n", e.what());
        return 2;
    }
    if (!opt.shard.empty()) parse_shard(opt.shard, opt.shard_k, opt.shard_n);
    const char* launcher = mpi_launcher_variable();
    if (launcher && !opt.mpi)
        throw UsageError(std::string("started by an MPI launcher (") + launcher +
                         " is set) without --mpi: every rank would render and write the same image");
    if (opt.mpi && !mpi_available())
        throw UsageError("--mpi: this streamrt was built without MPI support (cmake -DSTREAMRT_MPI=ON)");
    if (opt.mpi && !launcher && !std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMI_SIZE"))
        throw UsageError("--mpi: not started by an MPI launcher (mpirun -np N streamrt --mpi ...)");
    if (opt.resume && opt.checkpoint.empty()) throw UsageError("--resume needs --checkpoint FILE");
    if (opt.compare && opt.tiled())
        throw UsageError("--compare renders whole images: not with --mpi, --shard, --checkpoint or --tile-costs");
    if (opt.mpi && opt.shard_n > 0) throw UsageError("--shard splits a render without MPI: not with --mpi");
    if (opt.mpi && !opt.frames.empty())
        throw UsageError("--frames: not with --mpi (render frames as a job array, or --frames with --shard; "
                         "docs/distributed.md)");
    // From here on Ctrl-C (or SIGTERM) asks the render to stop; nothing is written then.
    std::signal(SIGINT, on_sigint);
    std::signal(SIGTERM, on_sigint);
    if (opt.mpi) return run_mpi(opt, argc, argv);

    // The whole process's phases, reported on the summary line: reading, set-up (inside
    // render_once), rendering and writing.
    auto phase_start = Clock::now();
    SceneBundle bundle;
    Scene loaded = opt.tiled() ? load_scene_bundled(opt.scene_path, opt.jobs, bundle)
                               : load_scene(opt.scene_path, opt.jobs);
    const double read_seconds = since(phase_start);
    Job job = make_job(opt, std::move(loaded), true, true);
    job.read_seconds = read_seconds;
    const RenderSettings& s = job.scene.settings;
    const FramePlan frames = plan_frames(opt, s);
    if (opt.check_only) {
        if (!opt.quiet)
            std::printf("%s: ok (%zu objects, %zu lights, %dx%d, spp %d, degree %d)\n", opt.scene_path.c_str(),
                        job.scene.objects.size(), job.scene.lights.size(), s.width, s.height, s.spp, s.degree);
        return 0;
    }
    if (g_cancel.load()) throw Interrupted{};
    Parallelism par(opt.jobs);
    // ---- animation: --frames / image frames= (scene/animation.h) ----
    if (frames.any) return render_frames(opt, job, par, bundle, frames);
    // A still picture of an animated scene is frame 0, also in the output name's %d.
    if (job.scene.animation) job.scene.settings.output = frame_output_name(s.output, 0).value_or(s.output);
    std::unique_ptr<PreparedRender> prepared;
    return render_picture(opt, job, par, bundle, prepared);
}

/// One picture: tile by tile (shards, checkpoints, tile costs), both engines (--compare) or
/// the chosen one. `prepared`: the engine's set-up, kept from frame to frame (animation);
/// made when null (--compare makes its own two).
int render_picture(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle,
                   std::unique_ptr<PreparedRender>& prepared) {
    if (opt.tiled()) return render_tiled(opt, job, par, bundle, nullptr, prepared);
    const RenderSettings& s = job.scene.settings;
    const EngineKind engine = job.engine;
    EngineOptions& eo = job.eo;
    WriteOptions wo;
    wo.par = &par;
    wo.cancel = &g_cancel;

    const auto render_once = [&](EngineKind which, bool show_progress) {
        RenderProgress progress;
        progress.cancel = &g_cancel;
        progress.tiles_total = tile_count(s.width, s.height);
        std::unique_ptr<PreparedRender> own;
        if (opt.compare) own = prepare(job, which, true);
        else if (!prepared) prepared = prepare(job, which, false);
        PreparedRender& ready = opt.compare ? *own : *prepared;
        ProgressDisplay display(progress, show_progress && !opt.quiet && ::isatty(2));
        RenderResult r = render_prepared(ready, par, &progress);
        display.stop();
        if (g_cancel.load()) throw Interrupted{};
        return r;
    };

    if (opt.compare) {
        // Both engines; the stream engine's picture is the one written, its profile the one
        // reported.
        StreamProfile* const stream_profile = eo.profile;
        eo.profile = nullptr;
        const RenderResult base = render_once(EngineKind::Recursive, true);
        eo.profile = stream_profile;
        const RenderResult str = render_once(EngineKind::Stream, true);
        if (!write_image(s.output, str.image, display_of(s), wo)) throw Interrupted{};
        const ImageDifference d = compare_images(str.image, base.image);
        std::printf("%s: %dx%d, spp %d, degree %d, -j%d, isa %s\n", opt.scene_path.c_str(), s.width, s.height, s.spp,
                    s.degree, par.jobs(), isa_name(eo.isa));
        std::printf("recursive: %.3f s, %llu rays (%.2f Mrays/s)\n", base.seconds,
                    (unsigned long long)base.counts.total(), base.counts.total() / std::max(base.seconds, 1e-9) / 1e6);
        std::printf("stream:    %.3f s, %llu rays (%.2f Mrays/s)\n", str.seconds,
                    (unsigned long long)str.counts.total(), str.counts.total() / std::max(str.seconds, 1e-9) / 1e6);
        std::printf("speedup:   %.2fx\n", base.seconds / std::max(str.seconds, 1e-9));
        std::printf("difference (stream vs recursive, calibrated): max %.5f, rmse %.6f, psnr %.2f dB, "
                    "pixels off by > 1/255: %.4f%%\n",
                    d.max_abs, d.rmse, d.psnr, 100.0 * d.share_over);
        std::printf("image (stream engine) -> %s\n", s.output.c_str());
        report_profile(opt, job.profile.get());
        return 0;
    }

    const RenderResult r = render_once(engine, true);
    const auto phase_start = Clock::now();
    if (!write_image(s.output, r.image, display_of(s), wo)) throw Interrupted{};
    const double write_seconds = since(phase_start);
    report_profile(opt, job.profile.get());
    print_summary(opt, job, par.jobs(), "", r.seconds, r.counts, r.setup_seconds, write_seconds);
    return 0;
}


/// --frames A..B or image frames=A..B: each frame is one picture written to the output name
/// with the frame number put in its printf-style %d (out_%04d.png), the engine's set-up
/// updated from frame to frame (only what moved is rebuilt).
int render_frames(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const FramePlan& plan) {
    const std::string pattern = job.scene.settings.output;
    std::unique_ptr<PreparedRender> prepared;
    for (int f = plan.first; f <= plan.last; ++f) {
        const FrameChange change = set_frame(job.scene, f);
        job.frame = f;
        job.scene.settings.output = frame_output_name(pattern, f).value_or(pattern);
        if (prepared) prepared->update(job.scene, change);
        if (const int status = render_picture(opt, job, par, bundle, prepared); status != 0) return status;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (...) {
        // Under an MPI launcher every rank would say the same: rank 0 speaks for them.
        return report_error(std::current_exception(), launcher_rank() != 0);
    }
}
