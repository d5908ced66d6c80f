#pragma once
// What the reader benchmarks (parse_bench, obj_bench) share: their command line
// (FILE, -r RUNS, -j JOBS...) and the median of their timings.
#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

struct ReaderBenchArgs {
    std::string path;
    int runs = 5;
    std::vector<int> jobs;  ///< -j values, in order given (default 1, 2)
};

inline ReaderBenchArgs parse_reader_bench_args(int argc, char** argv, std::string default_path) {
    ReaderBenchArgs a{std::move(default_path), 5, {}};
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-r" && i + 1 < argc) a.runs = std::max(1, std::atoi(argv[++i]));
        else if (arg == "-j" && i + 1 < argc) a.jobs.push_back(std::max(1, std::atoi(argv[++i])));
        else a.path = arg;
    }
    if (a.jobs.empty()) a.jobs = {1, 2};
    return a;
}

inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
