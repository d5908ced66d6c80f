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
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "scene/scene_bvh.h"
#include "core/error.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "kernels/kernel_table.h"
#include "parallel/parallelism.h"
#include "driver/limits.h"
#include "driver/render.h"
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
};

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
    // access() says yes to root everywhere; creating the file is what matters (read-only
    // file systems, /proc, ...). Probe with a temporary name, removed at once.
    const fs::path probe = dir / ("." + target.filename().string() + ".probe" + std::to_string(::getpid()));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
        throw UsageError("output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    ::close(fd);
    ::unlink(probe.c_str());
}

void check_output_path(const std::string& out, const std::string& scene_path) {
    if (!image_format_for(out))
        throw UsageError("output '" + out + "': unknown image format (expected .ppm, .png or .pfm)");
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

int run(int argc, char** argv) {
    Options opt;
    CLI::App app{"streamrt: a SIMD ray-stream ray tracer for .cfg scenes (see docs/scene-format.md)", "streamrt"};
    app.add_option("scene", opt.scene_path, "Scene file (.cfg)")->required();
    app.add_option("-j,--jobs", opt.jobs, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
    app.add_option("-o,--output", opt.output, "Output image (.ppm, .png or .pfm); overrides the scene's");
    app.add_option("--spp", opt.spp, "Samples per pixel")->check(CLI::Range(1, 65536));
    app.add_option("--width", opt.width, "Image width in pixels")->check(CLI::Range(1, 32768));
    app.add_option("--height", opt.height, "Image height in pixels")->check(CLI::Range(1, 32768));
    app.add_option("--degree", opt.degree, "Shading degree 0..5 (handout)")->check(CLI::Range(0, 5));
    app.add_option("--depth", opt.depth, "Maximum bounces")->check(CLI::Range(0, 256));
    app.add_option("--cutoff", opt.cutoff,
                   "Weight cut-off: reflected and refracted rays worth less than this in every channel are not "
                   "traced (default 0: all; overrides the scene's image cutoff=)")
        ->check(CLI::Range(0.0, 1.0));
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
        ->check(CLI::IsMember({"simd", "sorted", "gathered", "scalar"}));
    app.add_flag("--compare", opt.compare, "Render with both engines and report times, speedup and image difference");
    app.add_option("--sampler", opt.sampler, "Pixel sampling: stratified, grid or random")
        ->check(CLI::IsMember({"stratified", "grid", "random"}));
    app.add_flag("-q,--quiet", opt.quiet, "No progress bar and no summary line");
    app.add_flag("--check", opt.check_only, "Validate the scene and the output path, render nothing");
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
        // One line, like every other error (CLI11's own report adds a second line).
        std::fprintf(stderr, "streamrt: %s (see --help)\n", e.what());
        return 2;
    }
    // From here on Ctrl-C (or SIGTERM) asks the render to stop; nothing is written then.
    std::signal(SIGINT, on_sigint);
    std::signal(SIGTERM, on_sigint);

    // The whole process's phases, reported on the summary line: reading, set-up (inside
    // render_once), rendering and writing.
    using Clock = std::chrono::steady_clock;
    const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
    auto phase_start = Clock::now();
    Scene scene = load_scene(opt.scene_path, opt.jobs);
    const double read_seconds = since(phase_start);
    RenderSettings& s = scene.settings;
    if (opt.spp) s.spp = *opt.spp;
    if (opt.width) s.width = *opt.width;
    if (opt.height) s.height = *opt.height;
    if (opt.degree) s.degree = *opt.degree;
    if (opt.depth) s.depth = *opt.depth;
    if (opt.cutoff) s.cutoff = *opt.cutoff;
    if (opt.sampler == "grid") s.pattern = SamplePattern::Grid;
    if (opt.sampler == "random") s.pattern = SamplePattern::Random;
    if (opt.sampler == "stratified") s.pattern = SamplePattern::Stratified;
    if (!opt.output.empty()) s.output = opt.output;
    check_output_path(s.output, opt.scene_path);
    if (!opt.profile_json.empty()) check_writable_path(opt.profile_json, opt.scene_path);
    // Refuse, before allocating anything big, a render that cannot fit in this machine.
    const EngineKind engine = opt.engine == "recursive" ? EngineKind::Recursive : EngineKind::Stream;
    const int jobs = opt.jobs > 0 ? opt.jobs : default_jobs();
    check_render_memory(scene, engine == EngineKind::Stream || opt.compare, jobs);
    if (opt.check_only) {
        if (!opt.quiet)
            std::printf("%s: ok (%zu objects, %zu lights, %dx%d, spp %d, degree %d)\n", opt.scene_path.c_str(),
                        scene.objects.size(), scene.lights.size(), s.width, s.height, s.spp, s.degree);
        return 0;
    }

    accel::accel_config().mode = opt.accel == "bvh"    ? accel::AccelMode::Bvh
                                 : opt.accel == "flat" ? accel::AccelMode::Flat
                                                       : accel::AccelMode::Auto;
    if (g_cancel.load()) throw Interrupted{};
    Parallelism par(opt.jobs);
    EngineOptions eo;
    if (!opt.isa.empty()) {
        if (engine == EngineKind::Recursive && !opt.compare)
            throw UsageError("--isa chooses the stream engine's kernels; the recursive engine has none (scalar, double)");
        parse_isa(opt.isa, eo.isa);
        if (!isa_supported(eo.isa)) throw UsageError("--isa " + opt.isa + ": this CPU does not support it");
    }
    eo.shade = opt.shade == "scalar"     ? ShadeMode::Scalar
               : opt.shade == "sorted"   ? ShadeMode::Sorted
               : opt.shade == "gathered" ? ShadeMode::Gathered
                                         : ShadeMode::Auto;
    StreamProfile profile;
    const bool profiling = opt.profile || !opt.profile_json.empty();
    if (profiling) eo.profile = &profile;
    if (profiling && engine != EngineKind::Stream && !opt.compare)
        throw UsageError("--profile needs the stream engine");
    WriteOptions wo;
    wo.par = &par;
    wo.cancel = &g_cancel;
    // The profile, as text and/or JSON (written like images: whole, or not at all).
    const auto report_profile = [&] {
        if (opt.profile) std::printf("%s", profile.text().c_str());
        if (!opt.profile_json.empty()) write_text_file(opt.profile_json, profile.json());
    };

    const auto render_once = [&](EngineKind which, bool show_progress) {
        RenderProgress progress;
        progress.cancel = &g_cancel;
        progress.tiles_total = tile_count(s.width, s.height);
        const auto prepared = prepare_render(scene, which, eo);
        // An engine rendering from its own tables no longer needs the scene's object
        // records (128 bytes each; 128 MB at 1e6 objects): give them back before rendering.
        if (!prepared->reads_scene_objects() && !opt.compare) {
            std::vector<Object>().swap(scene.objects);
            std::vector<ObjectLoc>().swap(scene.object_locs);
        }
        ProgressDisplay display(progress, show_progress && !opt.quiet && ::isatty(2));
        RenderResult r = render_prepared(*prepared, par, &progress);
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
        if (!write_image(s.output, str.image, s.calibration, wo)) throw Interrupted{};
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
        report_profile();
        return 0;
    }

    const RenderResult r = render_once(engine, true);
    phase_start = Clock::now();
    if (!write_image(s.output, r.image, s.calibration, wo)) throw Interrupted{};
    const double write_seconds = since(phase_start);
    report_profile();
    if (!opt.quiet) {
        const double mrays = r.counts.total() / std::max(r.seconds, 1e-9) / 1e6;
        std::printf("%s: %dx%d, spp %d, degree %d, %s engine, -j%d: %.3f s, %llu rays (%.2f Mrays/s), set-up %.3f s -> %s"
                    " (read %.3f s, set-up %.3f s, render %.3f s, write %.3f s)\n",
                    opt.scene_path.c_str(), s.width, s.height, s.spp, s.degree, engine_name(engine), par.jobs(),
                    r.seconds, static_cast<unsigned long long>(r.counts.total()), mrays, r.setup_seconds,
                    s.output.c_str(), read_seconds, r.setup_seconds, r.seconds, write_seconds);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const Interrupted&) {
        std::fprintf(stderr, "streamrt: interrupted, no image written\n");
        return 130;
    } catch (const SceneError& e) {
        std::fprintf(stderr, "streamrt: %s\n", e.what());
        return 2;
    } catch (const UsageError& e) {
        std::fprintf(stderr, "streamrt: %s\n", e.what());
        return 2;
    } catch (const RenderError& e) {
        std::fprintf(stderr, "streamrt: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "streamrt: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "streamrt: %s\n", e.what());
        return 1;
    }
}
