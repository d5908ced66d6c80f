#pragma once
// What the reader benchmarks (parse_bench, obj_bench) share: their command line
// (FILE, -r RUNS, -j JOBS...) and the median of their timings.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

struct ReaderBenchArgs {
    std::string path;
    int runs = 5;
    std::vector<int> jobs;  ///< -j values, in order given (default 1, 2)
};

/// -h / --help prints the usage and exits 0; any other word starting with '-' is refused (exit
/// 2) rather than taken for the file (which the benchmarks write when it is missing).
inline ReaderBenchArgs parse_reader_bench_args(int argc, char** argv, std::string default_path) {
    ReaderBenchArgs a{std::move(default_path), 5, {}};
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-r" && i + 1 < argc) a.runs = std::max(1, std::atoi(argv[++i]));
        else if (arg == "-j" && i + 1 < argc) a.jobs.push_back(std::max(1, std::atoi(argv[++i])));
        else if (arg == "-h" || arg == "--help") {
            std::printf("usage: %s [FILE] [-r RUNS] [-j JOBS]... (default FILE %s, written when missing)\n", argv[0],
                        a.path.c_str());
            std::exit(0);
        } else if (arg.size() > 1 && arg[0] == '-') {
            std::fprintf(stderr, "%s: unknown option %s (usage: %s [FILE] [-r RUNS] [-j JOBS]...)\n", argv[0],
                         arg.c_str(), argv[0]);
            std::exit(2);
        } else {
            a.path = arg;
        }
    }
    if (a.jobs.empty()) a.jobs = {1, 2};
    return a;
}

inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
