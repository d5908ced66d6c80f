// The streamrt command: its options, the checks between them, and the dispatch to a picture,
// frames, a tiled or an MPI render. The program (main.cpp) and the Python module's
// `python -m streamrt` (python/module.cpp) both run it through run_command.
#include "cli/cli.h"
#include "cli/progress.h"
#include "core/memory_budget.h"
#include "core/nearest_name.h"
#include "preview/serve.h"

namespace streamrt::cli {

extern "C" void on_sigint(int) { g_cancel.store(true); }

namespace {

/// A whole number, sign and digits only: CLI11's Range would read "4.5" as out of range,
/// which sends the user looking at the bounds instead of the decimal point.
const CLI::Validator kInteger(
    [](std::string& v) {
        std::size_t i = !v.empty() && (v[0] == '-' || v[0] == '+') ? 1 : 0;
        if (i == v.size()) return "'" + v + "' is not an integer";
        for (; i < v.size(); ++i)
            if (v[i] < '0' || v[i] > '9') return "'" + v + "' is not an integer";
        return std::string();
    },
    "INT", "integer");

/// The one line for a command line CLI11 refused: an unknown option gets the nearest known
/// one when it is a likely slip ("--sp" for "--spp").
std::string parse_error_line(const CLI::App& app, const CLI::ParseError& e, const std::vector<std::string>& args) {
    if (!dynamic_cast<const CLI::ExtrasError*>(&e)) return e.what();
    std::vector<std::string> names;
    for (const CLI::Option* o : app.get_options()) {
        for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
        for (const std::string& s : o->get_snames()) names.push_back("-" + s);
    }
    for (auto it = args.rbegin(); it != args.rend(); ++it) {  // args are reversed for CLI11
        const std::string& a = *it;
        if (a.size() < 2 || a[0] != '-') continue;
        const std::string name = a.substr(0, a.find('='));
        if (std::find(names.begin(), names.end(), name) != names.end()) continue;
        if (const auto near = nearest_name(name, names))
            return "unknown option '" + name + "': did you mean '" + *near + "'?";
    }
    return e.what();
}

}  // namespace

int run(int argc, char** argv) {
    if (argc >= 2 && std::string(argv[1]) == "merge") return run_merge(argc - 1, argv + 1);
    if (argc >= 2 && std::string(argv[1]) == "serve") return preview::run_serve(argc - 1, argv + 1);
    // "--profile json FILE" reads as the flag, then a scene named "json": say what was meant.
    for (int i = 1; i + 1 < argc; ++i)
        if (std::string(argv[i]) == "--profile" && (std::string(argv[i + 1]) == "json" || std::string(argv[i + 1]) == "text"))
            throw UsageError(std::string("--profile ") + argv[i + 1] + ": the format is joined to the option, --profile=" +
                             argv[i + 1] + (std::string(argv[i + 1]) == "json" ? " FILE (e.g. --profile=json prof.json)" : ""));
    Options opt;
    CLI::App app{"streamrt: a SIMD ray-stream ray tracer for .cfg scenes (see docs/scene-format.md)", "streamrt"};
    app.footer("Also: streamrt merge PART... -o OUT (the parts of --shard renders); streamrt serve SCENE [--port P] "
               "(a live preview in the browser, docs/preview.md)");
    app.add_option("scene", opt.scene_path, "Scene file (.cfg)")->required();
    app.add_option("-j,--jobs", opt.jobs, "Worker threads (default: all cores)")->check(kInteger)->check(CLI::Range(1, 1024));
    app.add_option("-o,--output", opt.output, "Output image (" + image_format_extensions() + "); overrides the scene's");
    app.add_option("--memory-limit", opt.memory_limit,
                   "The most memory the process may hold, e.g. 4G or 512M (default: the available memory, within "
                   "a control group's limit, less a margin); reading, building, rendering and writing count against it");
    app.add_option("--spp", opt.spp, "Samples per pixel")->check(kInteger)->check(CLI::Range(1, 65536));
    app.add_option("--width", opt.width, "Image width in pixels")->check(kInteger)->check(CLI::Range(1, 32768));
    app.add_option("--height", opt.height, "Image height in pixels")->check(kInteger)->check(CLI::Range(1, 32768));
    app.add_option("--degree", opt.degree, "Shading degree 0..5 (handout), 6: global illumination (path tracing)")
        ->check(kInteger)
        ->check(CLI::Range(0, 6));
    app.add_option("--depth", opt.depth, "Maximum bounces")->check(kInteger)->check(CLI::Range(0, 256));
    app.add_option("--cutoff", opt.cutoff,
                   "Weight cut-off: reflected and refracted rays worth less than this in every channel are not "
                   "traced (default 0.001; 0 traces every ray; overrides the scene's image cutoff=)")
        ->check(CLI::Range(0.0, 1.0));
    app.add_option("--light-samples", opt.light_samples,
                   "Shadow rays per shaded point of every area light (overrides the lights' samples=)")
        ->check(kInteger)->check(CLI::Range(1, 4096));
    app.add_option("--engine", opt.engine, "Renderer: stream (SIMD ray streams) or recursive (the handout's baseline)")
        ->check(CLI::IsMember(names_vector(kEngineNames)));
    app.add_option("--isa", opt.isa, "Force the stream kernels' level: sse2, sse4.2, avx2 or avx512 (default: best the CPU has)")
        ->check(CLI::IsMember(names_vector(kIsaNames)));
    app.add_option("--accel", opt.accel,
                   "Object hierarchy: auto (the BVH above a measured object count), bvh (always) or flat (the "
                   "handout's loop over all objects)")
        ->check(CLI::IsMember(names_vector(accel::kAccelModeNames)));
    app.add_flag("--profile", opt.profile, "Print per-stage throughput of the stream engine");
    app.add_option("--profile-json", opt.profile_json, "Write the profile as JSON to FILE (also: --profile=json FILE)");
    app.add_option("--shade", opt.shade,
                   "Stream shade stage: simd (default: hits regrouped by object up to 8192 objects, by material and "
                   "kind above), sorted, gathered or scalar (for measurement)")
        ->check(CLI::IsMember(names_vector(kShadeModeNames)))
        ->group("");  // a measuring switch (docs/performance.md), not in the user's --help
    app.add_option("--mesh-hybrid", opt.mesh_hybrid,
                   "Stream engine, meshes: packets of reflected and refracted rays that have scattered (from the "
                   "fourth bounce on) walk a mesh's tree as packets until at most N rays reach a node, then one "
                   "by one (default 16; 0: packets only)")
        ->check(kInteger)->check(CLI::Range(0, 64));
    app.add_option("--colorspace", opt.colorspace, "8-bit output encoding: srgb (default) or linear (the handout's)")
        ->check(CLI::IsMember(names_vector(kColorSpaceNames)));
    app.add_option("--tonemap", opt.tonemap, "Tone curve before calibration: clamp (default) or reinhard")
        ->check(CLI::IsMember(names_vector(kTonemapNames)));
    app.add_option("--exposure", opt.exposure, "Multiplier of the linear values before the tone curve")
        ->check(CLI::Range(1e-6, 1e6));
    app.add_flag("--compare", opt.compare, "Render with both engines and report times, speedup and image difference");
    app.add_option("--sampler", opt.sampler, "Pixel sampling: stratified, grid or random")
        ->check(CLI::IsMember(names_vector(kSamplePatternNames)));
    app.add_option("--adaptive", opt.adaptive,
                   "Adaptive sampling: a pixel of n samples stops once the standard error of its mean (RMS over R, G, "
                   "B) is at most T (n / 16)^(3/4) (T at 16 samples, e.g. 0.03); --spp is the most it takes (without it: the "
                   "larger of 64 and the scene's spp, or the scene's spp when the scene asks for adaptive sampling)")
        ->check(CLI::Range(0.0, 1.0));
    app.add_option("--target-error", opt.target_error,
                   "Adaptive sampling until the image's estimated RMSE is at most E (the cap as for --adaptive; the "
                   "closing line says when the cap or the clock stopped it first)")
        ->check(CLI::Range(1e-9, 1.0));
    app.add_option("--time-limit", opt.time_limit,
                   "Adaptive sampling: stop refining after S seconds of rendering and write the picture so far")
        ->check(CLI::Range(1e-9, 1e9));
    app.add_option("--aov", opt.aov,
                   "samples=FILE: write each pixel's sample count and estimated error (.pfm or .exr; adaptive)");
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
        if (launcher_rank() == 0)
            std::fprintf(stderr, "streamrt: %s (see --help)\n", parse_error_line(app, e, args).c_str());
        return 2;
    }
    // An empty name would silently mean "none given" (for -o: the scene's output=).
    for (const char* file_option : {"-o", "--profile-json", "--checkpoint", "--tile-costs", "--aov"})
        if (app.count(file_option) > 0 && app.get_option(file_option)->as<std::string>().empty())
        {
            const std::string o = file_option;
            throw UsageError((o == "--profile-json" ? "--profile=json" : o) + ": an empty file name" +
                             (o == "-o" ? " (leave -o out to write the scene's output=)" : ""));
        }
    if (!opt.shard.empty()) parse_shard(opt.shard, opt.shard_k, opt.shard_n);
    if (!opt.memory_limit.empty()) MemoryBudget::set_limit(parse_memory_size(opt.memory_limit));
    const char* launcher = mpi_launcher_variable();
    if (launcher && !opt.mpi)
        throw UsageError(std::string("started by an MPI launcher (") + launcher +
                         " is set) without --mpi: every rank would render and write the same image");
    if (std::string why; opt.mpi && !mpi_available(&why))
        throw UsageError("--mpi: this streamrt has no MPI support (" + why + "; cmake -DSTREAMRT_MPI=ON)");
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
    // Immutable from here on (scene/scene.h): the job renders it with its own settings.
    auto loaded = std::make_shared<const Scene>(opt.tiled() ? load_scene_bundled(opt.scene_path, opt.jobs, bundle)
                                                            : load_scene(opt.scene_path, opt.jobs));
    const double read_seconds = since(phase_start);
    Job job = make_job(opt, std::move(loaded), true, true);
    job.read_seconds = read_seconds;
    const RenderSettings& s = job.render_settings;
    const FramePlan frames = plan_frames(opt, s);
    if (opt.check_only) {
        if (!opt.quiet)
            std::printf("%s: ok (%zu objects, %zu lights, %dx%d, spp %d, degree %d)\n", opt.scene_path.c_str(),
                        job.scene->objects.size(), job.scene->lights.size(), s.width, s.height, s.spp, s.degree);
        return 0;
    }
    if (g_cancel.load()) throw Interrupted{};
    Parallelism par(opt.jobs);
    // ---- animation: --frames / image frames= (scene/animation.h) ----
    if (frames.any) return render_frames(opt, job, par, bundle, frames);
    std::unique_ptr<PreparedRender> prepared;
    return render_picture(opt, job, par, bundle, prepared);
}

int run_command(int argc, char** argv) {
    g_cancel.store(false);  // a command run again in one process (the Python module) starts afresh
    try {
        return run(argc, argv);
    } catch (...) {
        // Under an MPI launcher every rank would say the same: rank 0 speaks for them.
        return report_error(std::current_exception(), launcher_rank() != 0);
    }
}

}  // namespace streamrt::cli
