#pragma once
// The one owner of threads: every parallel loop goes through here, so -j is honoured.
// The only header that includes TBB.
// STREAMRT_STD_THREADS=1 (only scripts/sanitize.sh tsan-std sets it) runs every loop on
// plain std::threads instead: the ThreadSanitizer fallback for a machine that cannot build
// oneTBB with TSan. ThreadSanitizer builds normally use oneTBB built with -fsanitize=thread
// (scripts/sanitize.sh tsan), so the scheduling that ships is the one checked.
#ifndef STREAMRT_STD_THREADS
#define STREAMRT_STD_THREADS 0
#endif
#if STREAMRT_STD_THREADS
#include <atomic>
#include <thread>
#include <vector>
#else
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_invoke.h>
#include <oneapi/tbb/task_arena.h>
#endif

#include <algorithm>
#include <cstddef>
#include <utility>

namespace streamrt {

/// Both engines render square tiles of this side (the stream engine's per-tile buffers are
/// sized by it); the progress display counts them.
inline constexpr int kTileSize = 16;

/// How many tiles of kTileSize cover a width x height image.
inline int tile_count(int width, int height) {
    return ((width + kTileSize - 1) / kTileSize) * ((height + kTileSize - 1) / kTileSize);
}

/// A rectangle of pixels [x0, x1) x [y0, y1).
struct Tile {
    int x0, y0, x1, y1;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
};

/// The number of threads "all cores" means.
inline int default_jobs() {
#if STREAMRT_STD_THREADS
    return int(std::max(1u, std::thread::hardware_concurrency()));
#else
    return oneapi::tbb::info::default_concurrency();
#endif
}

#if STREAMRT_STD_THREADS
namespace parallel_detail {
/// Runs work() on `threads` threads (the caller is one of them).
template <class Work>
void run_on_threads(int threads, Work&& work) {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back([&] { work(); });
    work();
    for (std::thread& t : pool) t.join();
}
inline thread_local int invoke_depth = 0;
}  // namespace parallel_detail

class Parallelism {
  public:
    explicit Parallelism(int jobs) : jobs_(jobs > 0 ? jobs : default_jobs()) {}
    int jobs() const { return jobs_; }

    template <class Body>
    void for_each_tile(int width, int height, int tile, Body&& body) {
        const int nx = (width + tile - 1) / tile, ny = (height + tile - 1) / tile;
        std::atomic<int> next{0};
        parallel_detail::run_on_threads(std::min(jobs_, std::max(1, nx * ny)), [&] {
            for (int i = next++; i < nx * ny; i = next++) {
                const int tx = i % nx, ty = i / nx;
                body(i, Tile{tx * tile, ty * tile, std::min(width, (tx + 1) * tile), std::min(height, (ty + 1) * tile)});
            }
        });
    }

    template <class Body>
    void for_each_index(std::size_t n, std::size_t grain, Body&& body) {
        std::atomic<std::size_t> next{0};
        const std::size_t step = std::max<std::size_t>(1, grain);
        parallel_detail::run_on_threads(jobs_, [&] {
            for (std::size_t b = next.fetch_add(step); b < n; b = next.fetch_add(step))
                for (std::size_t i = b; i < std::min(n, b + step); ++i) body(i);
        });
    }

  private:
    int jobs_;
};

template <class A, class B>
inline void parallel_invoke(A&& a, B&& b) {
    // Two threads per level for the first levels of a recursive build, then sequential.
    if (parallel_detail::invoke_depth >= 3) {
        a();
        b();
        return;
    }
    std::thread other([&] {
        parallel_detail::invoke_depth = 4;  // the new thread recurses sequentially
        a();
    });
    ++parallel_detail::invoke_depth;
    b();
    --parallel_detail::invoke_depth;
    other.join();
}

template <class Body>
inline void parallel_for_index(std::size_t n, std::size_t grain, Body&& body) {
    Parallelism(default_jobs()).for_each_index(n, grain, std::forward<Body>(body));
}

#else

class Parallelism {
  public:
    /// jobs <= 0 means all cores.
    explicit Parallelism(int jobs)
        : jobs_(jobs > 0 ? jobs : default_jobs()),
          limit_(oneapi::tbb::global_control::max_allowed_parallelism, std::size_t(jobs_)),
          arena_(jobs_) {}

    int jobs() const { return jobs_; }

    /// body(tile_index, Tile) for every tile of a width x height image cut into tile x tile
    /// squares. Tiles depend only on the image size, never on -j, and are handed out
    /// dynamically (grain 1), so the picture is the same for every thread count.
    template <class Body>
    void for_each_tile(int width, int height, int tile, Body&& body) {
        const int nx = (width + tile - 1) / tile, ny = (height + tile - 1) / tile;
        arena_.execute([&] {
            oneapi::tbb::parallel_for(
                oneapi::tbb::blocked_range<int>(0, nx * ny, 1),
                [&](const oneapi::tbb::blocked_range<int>& r) {
                    for (int i = r.begin(); i != r.end(); ++i) {
                        const int tx = i % nx, ty = i / nx;
                        body(i, Tile{tx * tile, ty * tile, std::min(width, (tx + 1) * tile),
                                     std::min(height, (ty + 1) * tile)});
                    }
                },
                oneapi::tbb::simple_partitioner());
        });
    }

    /// body(i) for i in [0, n), in chunks of `grain`.
    template <class Body>
    void for_each_index(std::size_t n, std::size_t grain, Body&& body) {
        arena_.execute([&] {
            oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, n, grain),
                                      [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                                          for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                                      });
        });
    }

  private:
    int jobs_;
    oneapi::tbb::global_control limit_;
    oneapi::tbb::task_arena arena_;
};

/// Runs a() and b() possibly in parallel, in the caller's arena (so inside a Parallelism's
/// work, or after one was made, -j is honoured). For recursive builds (engine/accel).
template <class A, class B>
inline void parallel_invoke(A&& a, B&& b) {
    oneapi::tbb::parallel_invoke(std::forward<A>(a), std::forward<B>(b));
}

/// body(i) for i in [0, n), chunks of `grain`, in the caller's arena (see parallel_invoke).
template <class Body>
inline void parallel_for_index(std::size_t n, std::size_t grain, Body&& body) {
    oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, n, grain),
                              [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                                  for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                              });
}

#endif  // STREAMRT_STD_THREADS

}  // namespace streamrt
