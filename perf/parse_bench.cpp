// Timing program for the scene reader (docs/performance.md, "## Scene reading"). Not a test.
//
//   parse_bench [FILE] [-r RUNS] [-j J]...
//
// Reads FILE (default /tmp/reader_s1e6.cfg; written by scripts/perf_common.py with 1e6
// spheres on a plane when absent) with load_scene at each -j (default 1 and 2), RUNS times
// each (default 5), every run in a fresh child process so that each reports its own peak
// resident memory. Prints the median wall time, the MB/s it gives, the median CPU time
// (user + system, whole child) and the median peak RSS.
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "reader_bench_args.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

struct Run {
    double seconds = 0;
    double cpu = 0;  // user + system seconds of the whole child (the machine is shared: wall time
                     // alone says little when other builds hold the cores)
    double peak_mb = 0;
    long objects = 0;
};

/// One load_scene in a child process: its wall time (from the child) and its peak RSS.
bool run_child(const std::string& path, int jobs, Run& out) {
    int fd[2];
    if (pipe(fd) != 0) return false;
    const pid_t pid = fork();
    if (pid < 0) return false;
    if (pid == 0) {
        close(fd[0]);
        double msg[2] = {-1, 0};
        try {
            const auto t0 = std::chrono::steady_clock::now();
            const Scene s = load_scene(path, jobs);
            msg[0] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            msg[1] = double(s.objects.size());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "parse_bench: %s\n", e.what());
        }
        if (write(fd[1], msg, sizeof msg) != ssize_t(sizeof msg)) _exit(1);
        _exit(0);  // skips the Scene's destruction, which is not reading
    }
    close(fd[1]);
    double msg[2] = {-1, 0};
    const bool got = read(fd[0], msg, sizeof msg) == ssize_t(sizeof msg);
    close(fd[0]);
    int status = 0;
    rusage ru{};
    wait4(pid, &status, 0, &ru);
    if (!got || msg[0] < 0) return false;
    const auto secs = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    out = {msg[0], secs(ru.ru_utime) + secs(ru.ru_stime), double(ru.ru_maxrss) / 1024.0, long(msg[1])};
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    const ReaderBenchArgs args = parse_reader_bench_args(argc, argv, "/tmp/reader_s1e6.cfg");
    const std::string& path = args.path;
    const int runs = args.runs;
    const std::vector<int>& jobs = args.jobs;
    struct stat st{};
    if (stat(path.c_str(), &st) != 0) {
        const std::string cmd = "python3 -B " STREAMRT_SOURCE_DIR "/scripts/perf_common.py spheres 1000000 '" + path +
                                "' 1280 720 1 4 1";
        std::printf("writing %s: %s\n", path.c_str(), cmd.c_str());
        if (std::system(cmd.c_str()) != 0 || stat(path.c_str(), &st) != 0) {
            std::fprintf(stderr, "parse_bench: cannot write %s\n", path.c_str());
            return 1;
        }
    }
    const double mb = double(st.st_size) / 1e6;
    std::printf("%s: %.1f MB, %d runs per -j, medians\n", path.c_str(), mb, runs);
    for (const int j : jobs) {
        std::vector<double> secs, cpus, peaks;
        long objects = 0;
        for (int r = 0; r < runs; ++r) {
            Run run;
            if (!run_child(path, j, run)) return 1;
            secs.push_back(run.seconds);
            cpus.push_back(run.cpu);
            peaks.push_back(run.peak_mb);
            objects = run.objects;
        }
        const double t = median(secs);
        std::printf("-j%d: %.3f s  %.0f MB/s  cpu %.3f s  peak RSS %.0f MB  (%ld objects; runs %.3f .. %.3f s)\n", j,
                    t, mb / t, median(cpus), median(peaks), objects, *std::min_element(secs.begin(), secs.end()),
                    *std::max_element(secs.begin(), secs.end()));
    }
    return 0;
}
