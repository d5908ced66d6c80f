// What a large array's first writes cost: an array of N MiB made with the allocator the
// framebuffer had (std::allocator: 4 KiB pages) and with HugePageAllocator (2 MiB pages where
// transparent huge pages are on), written once (first touch: page faults and the kernel's
// clearing) and again (warm). docs/performance.md, "Fresh memory".
//
// usage: build/perf/fresh_memory_bench [MIB] [--runs N]
#include <malloc.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "bench_clock.h"
#include "core/memory_advice.h"

namespace {

struct Times {
    double first = 0, again = 0;
};

template <class Alloc>
Times write_twice(std::size_t bytes) {
    Alloc alloc;
    const std::size_t n = bytes / sizeof(float);
    float* p = alloc.allocate(n);
    const double t0 = streamrt::perf::now();
    std::fill_n(p, n, 1.f);
    const double t1 = streamrt::perf::now();
    std::fill_n(p, n, 2.f);
    const double t2 = streamrt::perf::now();
    volatile float sink = p[n / 2];
    (void)sink;
    alloc.deallocate(p, n);
    return {t1 - t0, t2 - t1};
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    std::size_t mib = 64;
    int runs = 7;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
        else if (std::atoi(argv[i]) > 0) mib = std::size_t(std::atoi(argv[i]));
        else {
            std::fprintf(stderr, "usage: fresh_memory_bench [MIB] [--runs N]\n");
            return 2;
        }
    }
    const std::size_t bytes = mib << 20;
    // Each array from fresh pages, as in a process that makes it once: without this, glibc
    // raises its mmap threshold after the first free and serves later runs from its heap.
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
    std::vector<double> first4k, again4k, first2m, again2m;
    for (int r = 0; r < runs; ++r) {  // alternated, so both see the same machine
        const Times a = write_twice<std::allocator<float>>(bytes);
        const Times b = write_twice<streamrt::HugePageAllocator<float>>(bytes);
        first4k.push_back(a.first), again4k.push_back(a.again);
        first2m.push_back(b.first), again2m.push_back(b.again);
    }
    const double pages = double(bytes) / 4096;
    std::printf("%zu MiB, medians of %d alternated runs\n", mib, runs);
    std::printf("allocator          first write ms  us per 4 KiB  second write ms\n");
    std::printf("std::allocator     %14.2f  %12.3f  %15.2f\n", median(first4k) * 1e3, median(first4k) * 1e6 / pages,
                median(again4k) * 1e3);
    std::printf("HugePageAllocator  %14.2f  %12.3f  %15.2f\n", median(first2m) * 1e3, median(first2m) * 1e6 / pages,
                median(again2m) * 1e3);
    return 0;
}
