// The render job from the command line, and the checks made before anything renders.
#include "cli/cli.h"
#include "cli/progress.h"

namespace streamrt::cli {

std::atomic<bool> g_cancel{false};

/// This process's rank when an MPI launcher started it (0 otherwise): messages that every
/// rank would print alike are printed by rank 0 only.
int launcher_rank() {
    for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const char* r = std::getenv(v)) return std::atoi(r);
    return 0;
}

[[noreturn]] void NamedBy::refuse(const std::string& name, const std::string& why) const {
    if (!option.empty()) throw UsageError((option.back() == '=' ? option : option + " ") + name + ": " + why);
    if (scene && scene->output_at.line > 0) throw SceneError(scene->output_at, "output=" + name + ": " + why);
    throw UsageError("output " + name + " (the scene's default): " + why);
}

void check_not_input(const Scene& scene, const std::string& out, const std::string& option,
                     const std::string& pattern) {
    const SceneInput* in = scene.input_at(out);
    if (!in) return;
    // A frame's file is named with the pattern it came from, which is what the user typed.
    const std::string named = pattern.empty() || pattern == out ? out : pattern + " (as " + out + ")";
    NamedBy{option, &scene}.refuse(named, "is an input of the scene (" + in->describe() + ")");
}

// A missing folder, a read-only folder or a folder are refused before any rendering starts
// (the scene's own files are refused by check_not_input), naming the option or the scene's
// output= that named the file: a user with both cannot tell which one a bare folder came from.
void check_writable_path(const std::string& out, const NamedBy& by) {
    std::error_code ec;
    const fs::path target = fs::absolute(out, ec);
    if (fs::is_directory(target, ec)) by.refuse(out, "is a folder");
    const fs::path dir = target.parent_path();
    if (!fs::is_directory(dir, ec)) by.refuse(out, "output folder '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0) by.refuse(out, "output folder '" + dir.string() + "' is not writable");
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
    if (fd < 0) by.refuse(out, "output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    ::close(fd);
}

void check_output_path(const std::string& out, const NamedBy& by) {
    if (!image_format_for(out)) by.refuse(out, "unknown image format (expected " + image_format_extensions() + ")");
    check_writable_path(out, by);
}


/// The command line's overrides of the scene's settings (driver/render_job.h: the Python
/// module builds its jobs from the same record).
RenderOverrides overrides_of(const Options& opt) {
    RenderOverrides o;
    o.width = opt.width, o.height = opt.height, o.spp = opt.spp, o.depth = opt.depth, o.degree = opt.degree;
    o.cutoff = opt.cutoff, o.light_samples = opt.light_samples, o.exposure = opt.exposure;
    o.adaptive = opt.adaptive, o.target_error = opt.target_error, o.time_limit = opt.time_limit;
    const auto text = [](const std::string& v) { return v.empty() ? std::nullopt : std::optional<std::string>(v); };
    o.sampler = text(opt.sampler), o.colorspace = text(opt.colorspace), o.tonemap = text(opt.tonemap);
    o.engine = opt.engine, o.accel = opt.accel, o.shade = opt.shade, o.mesh_hybrid = opt.mesh_hybrid;
    o.threads = opt.jobs;
    return o;
}

/// Applies the command line to a loaded scene and checks everything before rendering.
/// `writes`: this process writes the output (false on MPI ranks other than 0).
/// `check_isa`: --isa must be supported here (MPI ranks agree on it together instead).
Job make_job(const Options& opt, std::shared_ptr<const Scene> scene, bool writes, bool check_isa) {
    const EngineKind engine = value_named(kEngineNames, opt.engine).value_or(EngineKind::Stream);
    if (!opt.isa.empty() && engine == EngineKind::Recursive && !opt.compare)
        throw UsageError("--isa chooses the stream engine's kernels; the recursive engine has none (scalar, double)");
    if ((opt.profile || !opt.profile_json.empty()) && engine != EngineKind::Stream && !opt.compare)
        throw UsageError("--profile needs the stream engine");
    RenderOverrides overrides = overrides_of(opt);
    if (check_isa && !opt.isa.empty()) overrides.isa = opt.isa;  // checked against this CPU there
    if (!opt.output.empty()) overrides.output = opt.output;
    Job job;
    static_cast<RenderJob&>(job) = build_render_job(std::move(scene), overrides, opt.profile || !opt.profile_json.empty());
    job.animated = job.scene->animation != nullptr;
    if (!check_isa && !opt.isa.empty()) parse_isa(opt.isa, job.options.isa);  // MPI: the ranks agree on it later
    job.settings.isa = job.options.isa;
    const RenderSettings& s = job.render_settings;
    if (opt.mpi && s.frames_last > s.frames_first)
        throw UsageError("--mpi renders one picture, the scene's image frames= asks for several (render them as a job "
                         "array, docs/distributed.md)");
    // The image's target and the clock decide across the whole image at once: a tile
    // rendered alone (another process, a resumed journal) cannot know them.
    if ((opt.target_error || opt.time_limit) && opt.tiled())
        throw UsageError("--target-error and --time-limit decide over the whole image: not with --mpi, --shard, "
                         "--checkpoint or --tile-costs (--adaptive T is the same in every tile)");
    const std::string sample_map = sample_map_path(opt);
    if (!sample_map.empty() && (job.render_settings.adaptive == 0 || opt.tiled() || opt.compare))
        throw UsageError("--aov samples= needs adaptive sampling (--adaptive, --target-error or image adaptive=) on "
                         "one whole image (not --compare or a tiled render)");
    job.options.sample_map = !sample_map.empty();
    if (writes) {
        // No file written may be one the scene read (docs/scene-format.md, "Paths"): each is
        // checked by identity before anything renders, and named as the user named it.
        const Scene& scene = *job.scene;
        const std::string image_option = opt.output.empty() ? "" : "-o";
        const FramePlan frames = plan_frames(opt, s);
        if (frames.any) {
            for (int f = frames.first; f <= frames.last && f >= frames.first; ++f)
                check_not_input(scene, frame_output_name(s.output, f).value_or(s.output), image_option, s.output);
        } else {
            check_not_input(scene, job.animated ? frame_output_name(s.output, 0).value_or(s.output) : s.output,
                            image_option, s.output);
        }
        if (!sample_map.empty()) check_not_input(scene, sample_map, "--aov samples=", "");
        if (!opt.profile_json.empty()) check_not_input(scene, opt.profile_json, "--profile=json", "");
        if (!opt.tile_costs.empty()) check_not_input(scene, opt.tile_costs, "--tile-costs", "");
        if (!opt.checkpoint.empty()) check_not_input(scene, opt.checkpoint, "--checkpoint", "");
        if (!sample_map.empty()) check_writable_path(sample_map, {"--aov samples="});
        // A shard part is a tile file (docs/distributed.md), whatever its name.
        const NamedBy image_by{image_option, &scene};
        if (opt.shard_n > 0) check_writable_path(s.output, image_by);
        else check_output_path(s.output, image_by);
        if (!opt.profile_json.empty()) check_writable_path(opt.profile_json, {"--profile=json"});
        if (!opt.tile_costs.empty()) check_writable_path(opt.tile_costs, {"--tile-costs"});
    }
    // Refuse, before allocating anything big, a render that cannot fit in this machine.
    const int jobs = opt.jobs > 0 ? opt.jobs : default_jobs();
    check_render_memory(*job.scene, s, job.engine == EngineKind::Stream || opt.compare, jobs);
    return job;
}

/// The engine's set-up for the job's frame. The job then lets go of its scene, which nothing
/// here reads again (settings and output name are the job's): the recursive engine holds
/// it, and with the stream engine, which renders from its own tables, its object records
/// are freed (128 bytes each and 12 of statement places; 140 MB at 1e6 objects).
std::unique_ptr<PreparedRender> prepare(Job& job, EngineKind which, bool keep_scene) {
    auto prepared = prepare_job(job, which, job.frame);
    // An animated scene is kept: the next frames are made from it (scene/animation.h).
    if (!keep_scene && !job.animated) job.scene.reset();
    return prepared;
}

void report_profile(const Options& opt, const StreamProfile* profile) {
    if (!profile) return;
    if (opt.profile) std::printf("%s", profile->text().c_str());
    if (!opt.profile_json.empty()) write_text_file(opt.profile_json, profile->json());
}

std::string sample_map_path(const Options& opt) {
    if (opt.aov.empty()) return {};
    const std::string prefix = "samples=";
    const std::string path = opt.aov.rfind(prefix, 0) == 0 ? opt.aov.substr(prefix.size()) : std::string();
    if (path.empty()) throw UsageError("--aov " + opt.aov + ": expected samples=FILE");
    const ImageFormat* f = image_format_for(path);
    if (!f || f->display_encoded)
        throw UsageError("--aov samples=" + path + ": the sample map is written as .pfm or .exr (linear floats)");
    return path;
}

/// What the closing line adds when an adaptive render did not keep its request (empty when
/// it did): what was asked, what stopped it, and how to go further. A request cut short by
/// the cap used to end with exit status 0 and no word (issue 52).
std::string cut_short_note(const Options& opt, const Job& job, const AdaptiveSummary& a) {
    using Cut = AdaptiveSummary::Cut;
    const Cut cut = a.cut();
    if (cut == Cut::NotCut) return a.time_limited ? ", time limit reached" : "";
    char asked[96], why[256];
    if (a.target_error > 0)
        std::snprintf(asked, sizeof asked, "target error %g not reached", a.target_error);
    else
        std::snprintf(asked, sizeof asked, "threshold %g not reached", a.threshold);
    if (cut == Cut::TimeLimit) {
        std::snprintf(why, sizeof why, "the time limit (--time-limit %g s) stopped it", opt.time_limit.value_or(0));
    } else if (cut == Cut::Cap) {
        const char* from = job.adaptive_cap_from == AdaptiveCapFrom::Given   ? "--spp"
                           : job.adaptive_cap_from == AdaptiveCapFrom::Scene ? "the scene's spp; --spp raises it"
                                                                              : "the default; --spp raises it";
        std::snprintf(why, sizeof why, "%llu pixel(s) stopped at the cap of %d samples (%s)",
                      static_cast<unsigned long long>(a.above_at_cap), a.cap, from);
    } else {
        std::snprintf(why, sizeof why, "every pixel met its threshold %g (--adaptive: a smaller one goes further)",
                      a.threshold);
    }
    return std::string("; ") + asked + ": " + why;
}

/// The summary line.
void print_summary(const Options& opt, const Job& job, int jobs, const std::string& how, double seconds,
                   const RayCounts& counts, double setup_seconds, double write_seconds,
                   const std::optional<AdaptiveSummary>& adaptive) {
    if (opt.quiet) return;
    const RenderSettings& s = job.render_settings;
    const std::string frame = job.frame >= 0 ? ", frame " + std::to_string(job.frame) : "";
    const double mrays = counts.total() / std::max(seconds, 1e-9) / 1e6;
    char spp[512];
    if (adaptive)
        std::snprintf(spp, sizeof spp, "spp %.2f adaptive (at most %d, estimated error %.3g%s)", adaptive->mean_spp,
                      s.spp, adaptive->estimated_rmse, cut_short_note(opt, job, *adaptive).c_str());
    else
        std::snprintf(spp, sizeof spp, "spp %d", s.spp);
    std::printf("%s: %dx%d, %s, degree %d, %s engine%s, -j%d: %.3f s, %llu rays (%.2f Mrays/s), set-up %.3f s -> %s"
                " (read %.3f s, set-up %.3f s, render %.3f s, write %.3f s)\n",
                opt.scene_path.c_str(), s.width, s.height, spp, s.degree, engine_name(job.engine), (how + frame).c_str(), jobs,
                seconds, static_cast<unsigned long long>(counts.total()), mrays, setup_seconds, output_name(job).c_str(),
                job.read_seconds, setup_seconds, seconds, write_seconds);
}


/// Prints the error being handled (one line) and gives its exit status: 2 bad usage or bad
/// scene, 1 render or I/O failure, 130 interrupted. `quiet`: the status only.
int report_error(std::exception_ptr error, bool quiet) {
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

}  // namespace streamrt::cli
