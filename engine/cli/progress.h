#pragma once
// The progress bar of the streamrt command: elapsed time and ETA on stderr, when it is a terminal.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "render/render_stats.h"

namespace streamrt::cli {

inline std::string format_seconds(double s) {
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

}  // namespace streamrt::cli
