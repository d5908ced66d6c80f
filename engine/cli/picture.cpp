// One picture (one engine, or both with --compare) and animation frames.
#include "cli/cli.h"
#include "cli/progress.h"

namespace streamrt::cli {

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

std::string output_name(const Job& job) {
    const std::string& pattern = job.render_settings.output;
    const int frame = job.frame >= 0 ? job.frame : job.animated ? 0 : -1;
    return frame >= 0 ? frame_output_name(pattern, frame).value_or(pattern) : pattern;
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


/// One picture: tile by tile (shards, checkpoints, tile costs), both engines (--compare) or
/// the chosen one. `prepared`: the engine's set-up, kept from frame to frame (animation);
/// made when null (--compare makes its own two).
int render_picture(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle,
                   std::unique_ptr<PreparedRender>& prepared) {
    if (opt.tiled()) return render_tiled(opt, job, par, bundle, nullptr, prepared);
    const RenderSettings& s = job.render_settings;
    const std::string output = output_name(job);
    const EngineKind engine = job.engine;
    EngineOptions& eo = job.options;
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
        const auto write_start = Clock::now();
        if (!write_image(output, str.image, display_of(s), wo)) throw Interrupted{};
        const double write_seconds = since(write_start);
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
        report_profile(opt, job.profile.get());
        // Every render ends with the summary line (README): here the stream engine's, whose
        // picture was written, whatever --engine said.
        job.engine = EngineKind::Stream;
        print_summary(opt, job, par.jobs(), ", compared with the recursive engine", str.seconds, str.counts,
                      str.setup_seconds, write_seconds, str.adaptive);
        return 0;
    }

    const RenderResult r = render_once(engine, true);
    const auto phase_start = Clock::now();
    if (!write_image(output, r.image, display_of(s), wo)) throw Interrupted{};
    if (const std::string map = sample_map_path(opt); !map.empty() && r.adaptive) {
        Display floats;
        floats.exr = ExrPixels::Float;  // counts above 2048 are not all whole numbers in half
        if (!write_image(map, r.sample_map, floats, wo)) throw Interrupted{};
    }
    const double write_seconds = since(phase_start);
    if (job.profile) job.profile->adaptive = r.adaptive;
    report_profile(opt, job.profile.get());
    print_summary(opt, job, par.jobs(), "", r.seconds, r.counts, r.setup_seconds, write_seconds, r.adaptive);
    return 0;
}


/// --frames A..B or image frames=A..B: each frame is one picture written to the output name
/// with the frame number put in its printf-style %d (out_%04d.png), the engine's set-up
/// updated from frame to frame (only what moved is rebuilt). Each frame's scene is a new one
/// made from the job's, which stays as read.
int render_frames(const Options& opt, Job& job, Parallelism& par, const SceneBundle& bundle, const FramePlan& plan) {
    std::unique_ptr<PreparedRender> prepared;
    for (int f = plan.first; f <= plan.last; ++f) {
        if (prepared) update_job_frame(*prepared, job, job.frame, f);
        job.frame = f;
        if (const int status = render_picture(opt, job, par, bundle, prepared); status != 0) return status;
    }
    return 0;
}

}  // namespace streamrt::cli
