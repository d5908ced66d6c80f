#pragma once
// Per-stage throughput figures of the stream engine (streamrt --profile).
#include <array>
#include <chrono>
#include <ctime>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "render/adaptive.h"
#include "render/render_stats.h"

namespace streamrt {

enum class Stage : int { Generate, Intersect, Shade, Occlusion, Accumulate };
inline constexpr int kStageCount = 5;
const char* stage_name(Stage s);

struct StageFigures {
    std::uint64_t rays_in = 0, rays_out = 0;
    std::uint64_t nanoseconds = 0;      ///< thread CPU time in the stage, summed over threads
    std::uint64_t lanes_used = 0, lanes_total = 0;  ///< kernel stages: active lanes / lanes run
    StageFigures& operator+=(const StageFigures& o) {
        rays_in += o.rays_in;
        rays_out += o.rays_out;
        nanoseconds += o.nanoseconds;
        lanes_used += o.lanes_used;
        lanes_total += o.lanes_total;
        return *this;
    }
};

/// One ray generation's share of the two tracing stages (0 = camera rays, 1 = their first
/// bounce, ...): the rays intersected, by kind, and the shadow rays cast from their hits.
/// The times are the same thread CPU time as the stage table's, read by the same timers,
/// so a stage's generations add up to its row.
struct GenerationFigures {
    std::uint64_t rays = 0;  ///< rays intersected in this generation
    std::uint64_t primary = 0, reflected = 0, refracted = 0, diffuse = 0;  ///< `rays` by RayKind
    std::uint64_t intersect_ns = 0;  ///< intersect stage, thread CPU time
    std::uint64_t shadow_rays = 0;   ///< shadow rays cast from this generation's hits
    std::uint64_t occlusion_ns = 0;  ///< occlusion stage, thread CPU time
    GenerationFigures& operator+=(const GenerationFigures& o) {
        rays += o.rays;
        primary += o.primary;
        reflected += o.reflected;
        refracted += o.refracted;
        diffuse += o.diffuse;
        intersect_ns += o.intersect_ns;
        shadow_rays += o.shadow_rays;
        occlusion_ns += o.occlusion_ns;
        return *this;
    }
};

struct StreamProfile {
    std::array<StageFigures, kStageCount> stages{};
    std::vector<GenerationFigures> generations;  ///< index = generation (ray depth)
    RayCounts counts;
    double wall_seconds = 0;
    int threads = 1;
    std::string isa;
    int lanes = 0;
    std::vector<std::string> built;  ///< the stages and kernels this scene's pipeline has
    /// A whole-image adaptive render's outcome and phases (set by the front end after it).
    std::optional<AdaptiveSummary> adaptive;
    StreamProfile& operator+=(const StreamProfile& o) {
        for (int i = 0; i < kStageCount; ++i) stages[std::size_t(i)] += o.stages[std::size_t(i)];
        if (generations.size() < o.generations.size()) generations.resize(o.generations.size());
        for (std::size_t d = 0; d < o.generations.size(); ++d) generations[d] += o.generations[d];
        return *this;
    }
    /// Generation d's figures, made room for (profiling only).
    GenerationFigures& generation(int d) {
        if (generations.size() <= std::size_t(d)) generations.resize(std::size_t(d) + 1);
        return generations[std::size_t(d)];
    }
    std::string text() const;
    std::string json() const;
};

/// CPU time of the calling thread, in nanoseconds: stage figures stay meaningful on a
/// shared machine, where wall time also counts the time other processes held the core.
inline std::uint64_t thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return std::uint64_t(ts.tv_sec) * 1000000000ull + std::uint64_t(ts.tv_nsec);
}

/// Times a scope (thread CPU time) into a StageFigures when profiling; one branch when not.
/// `also` (optional, profiling only): a second counter that gets the same nanoseconds, e.g.
/// a generation's share of the stage (GenerationFigures).
class StageTimer {
  public:
    StageTimer(StageFigures* f, std::uint64_t* also = nullptr) : f_(f), also_(also) {
        if (f_) start_ = thread_cpu_ns();
    }
    ~StageTimer() {
        if (f_) {
            const std::uint64_t ns = thread_cpu_ns() - start_;
            f_->nanoseconds += ns;
            if (also_) *also_ += ns;
        }
    }

  private:
    StageFigures* f_;
    std::uint64_t* also_;
    std::uint64_t start_ = 0;
};

}  // namespace streamrt
