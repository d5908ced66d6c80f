#pragma once
// Per-stage throughput figures of the stream engine (streamrt --profile).
#include <array>
#include <chrono>
#include <ctime>
#include <cstdint>
#include <string>
#include <vector>

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

struct StreamProfile {
    std::array<StageFigures, kStageCount> stages{};
    RayCounts counts;
    double wall_seconds = 0;
    int threads = 1;
    std::string isa;
    int lanes = 0;
    std::vector<std::string> built;  ///< the stages and kernels this scene's pipeline has
    StreamProfile& operator+=(const StreamProfile& o) {
        for (int i = 0; i < kStageCount; ++i) stages[std::size_t(i)] += o.stages[std::size_t(i)];
        return *this;
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
class StageTimer {
  public:
    StageTimer(StageFigures* f) : f_(f) {
        if (f_) start_ = thread_cpu_ns();
    }
    ~StageTimer() {
        if (f_) f_->nanoseconds += thread_cpu_ns() - start_;
    }

  private:
    StageFigures* f_;
    std::uint64_t start_ = 0;
};

}  // namespace streamrt
