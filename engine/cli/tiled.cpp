// Rendering tile by tile: shard parts, checkpoint journals, tile costs, MPI ranks; and
// streamrt merge.
#include "cli/cli.h"
#include "cli/progress.h"

namespace streamrt::cli {

/// Renders tile by tile: shards, checkpoints, tile costs, and MPI (`mpi` set). On MPI ranks
/// other than 0, renders what rank 0 hands out and returns.
/// `prepared`: the engine's set-up, kept from frame to frame (animation); made when null.
int render_tiled(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const MpiSession* mpi,
                 std::unique_ptr<PreparedRender>& prepared) {
    const RenderSettings& s = job.render_settings;
    const std::string output = output_name(job);
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
    settings.isa = job.options.isa;  // MPI: the level the ranks agreed on
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
    // The resumed tiles' rays were traced by an earlier run: counted in this run's rate they
    // gave 2,331,886 Mrays/s.
    const RayCounts resumed_rays = assembly.counts();
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
        write_text_file(output, header.line() + "\n" + assembly.records(mine));
    } else {
        WriteOptions wo;
        wo.par = &par;
        wo.cancel = &g_cancel;
        if (!write_image(output, assembly.image(), display_of(s), wo)) throw Interrupted{};
    }
    const double write_seconds = since(write_start);
    if (!opt.tile_costs.empty()) write_text_file(opt.tile_costs, assembly.costs_csv());
    if (journal) journal->remove();
    if (job.profile && mpi) job.profile->threads = par.jobs();
    report_profile(opt, job.profile.get());
    if (opt.profile && mpi) std::printf("%s", rank_stats_text(ranks).c_str());
    std::string how = job.engine == EngineKind::Stream ? std::string(", isa ") + isa_name(job.options.isa) : "";
    if (mpi)
        how += ", " + std::to_string(mpi->size()) + (mpi->size() == 1 ? " rank" : " ranks") + " (" +
               opt.mpi_schedule + ")";
    if (opt.shard_n > 0) how += ", shard " + opt.shard;
    RayCounts traced = assembly.counts();
    traced.primary -= resumed_rays.primary, traced.shadow -= resumed_rays.shadow;
    traced.reflected -= resumed_rays.reflected, traced.refracted -= resumed_rays.refracted;
    traced.diffuse -= resumed_rays.diffuse;
    if (journal && journal->resumed() > 0)
        how += ", " + std::to_string(journal->resumed()) + " tiles resumed (" +
               std::to_string(resumed_rays.total()) + " rays traced before, not in the rate)";
    print_summary(opt, job, par.jobs(), how, seconds, traced, prepared->setup_seconds, write_seconds);
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
            auto scene = std::make_shared<const Scene>(load_scene_bundled(opt.scene_path, opt.jobs, bundle));
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
            job.emplace(make_job(opt, std::make_shared<const Scene>(load_scene_from_bundle(bundle, opt.jobs)), false,
                                 false));
            job->read_seconds = since(start);
        }
        // An animated scene: every rank renders its one frame, image frames=F or frame 0
        // (several frames are refused by make_job, --frames by run()); its scene is made
        // when the engine is prepared, its file name where the file is written.
        if (const RenderSettings& rs = job->render_settings; job->animated || rs.has_frames())
            job->frame = rs.has_frames() ? rs.frames_first : 0;
        // One kernel level for all: the one asked for if every rank has it, else the best
        // every rank has (float results differ in the last bits between levels).
        if (job->engine == EngineKind::Stream) {
            if (!opt.isa.empty()) {
                if (mpi.min_over_ranks(isa_supported(job->options.isa) ? 1 : 0) == 0) {
                    if (rank0) std::fprintf(stderr, "streamrt: --isa %s: not every rank's CPU supports it\n", opt.isa.c_str());
                    return 2;
                }
            } else {
                job->options.isa = Isa(mpi.min_over_ranks(int(best_isa())));
            }
        }
        if (opt.check_only) {
            if (rank0 && !opt.quiet)
                std::printf("%s: ok (%zu objects, %zu lights, %d ranks)\n", opt.scene_path.c_str(),
                            job->scene->objects.size(), job->scene->lights.size(), mpi.size());
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
    app.add_option("-o,--output", output, "Output image (" + image_format_extensions() + ")")->required();
    app.add_flag("-q,--quiet", quiet, "No summary line");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::fprintf(stderr, "streamrt merge: %s (see --help)\n", e.what());
        return 2;
    }
    // The parts are the merge's inputs: writing the image over one would lose it.
    for (const std::string& part : parts)
        if (same_file(output, part)) throw UsageError("-o " + output + ": is one of the parts being merged");
    check_output_path(output, {"-o"});
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

}  // namespace streamrt::cli
