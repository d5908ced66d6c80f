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
#include <atomic>
#include <cstddef>
#include <mutex>
#include <set>
#include <thread>
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

/// Tile number `index` of a width x height image cut into kTileSize squares, numbered row by
/// row from the top-left (the numbering of for_each_tile).
inline Tile tile_rect(int width, int height, int index) {
    const int nx = (width + kTileSize - 1) / kTileSize;
    const int tx = index % nx, ty = index / nx;
    return Tile{tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize),
                std::min(height, (ty + 1) * kTileSize)};
}

/// The number of threads "all cores" means.
inline int default_jobs() {
#if STREAMRT_STD_THREADS
    return int(std::max(1u, std::thread::hardware_concurrency()));
#else
    return oneapi::tbb::info::default_concurrency();
#endif
}

/// Notes every thread that runs a piece of a parallel loop of this file while it is alive
/// (one at a time): tests check with it that -j bounds the threads of a phase.
class ThreadProbe {
  public:
    ThreadProbe() { installed().store(this); }
    ~ThreadProbe() { installed().store(nullptr); }
    ThreadProbe(const ThreadProbe&) = delete;
    ThreadProbe& operator=(const ThreadProbe&) = delete;
    /// Distinct threads seen.
    std::size_t threads() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return ids_.size();
    }
    /// Called by the loops: notes the calling thread if a probe is installed.
    static void note() {
        if (ThreadProbe* p = installed().load(std::memory_order_relaxed)) {
            std::lock_guard<std::mutex> lock(p->mutex_);
            p->ids_.insert(std::this_thread::get_id());
        }
    }

  private:
    static std::atomic<ThreadProbe*>& installed() {
        static std::atomic<ThreadProbe*> probe{nullptr};
        return probe;
    }
    mutable std::mutex mutex_;
    std::set<std::thread::id> ids_;
};

#if STREAMRT_STD_THREADS
namespace parallel_detail {
/// Runs work() on `threads` threads (the caller is one of them).
/// The threads of the Parallelism::run() the calling thread is in (0: none, all cores).
inline thread_local int current_jobs = 0;
template <class Work>
void run_on_threads(int threads, Work&& work) {
    std::vector<std::thread> pool;
    const int jobs = current_jobs;
    for (int t = 1; t < threads; ++t)
        pool.emplace_back([&] {
            current_jobs = jobs;
            ThreadProbe::note();
            work();
        });
    ThreadProbe::note();
    work();
    for (std::thread& t : pool) t.join();
}
inline thread_local int invoke_depth = 0;
}  // namespace parallel_detail

class Parallelism {
  public:
    explicit Parallelism(int jobs) : jobs_(jobs > 0 ? jobs : default_jobs()) {}
    int jobs() const { return jobs_; }

    /// Runs f() so that the loops it calls (parallel_for_index, parallel_invoke) use at most
    /// jobs() threads; returns what f returns.
    template <class F>
    decltype(auto) run(F&& f) {
        struct Restore {
            int saved = parallel_detail::current_jobs;
            ~Restore() { parallel_detail::current_jobs = saved; }
        } restore;
        parallel_detail::current_jobs = jobs_;
        return f();
    }

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
    if (parallel_detail::invoke_depth >= 3 || parallel_detail::current_jobs == 1) {
        a();
        b();
        return;
    }
    std::thread other([&] {
        parallel_detail::invoke_depth = 4;  // the new thread recurses sequentially
        ThreadProbe::note();
        a();
    });
    ++parallel_detail::invoke_depth;
    b();
    --parallel_detail::invoke_depth;
    other.join();
}

template <class Body>
inline void parallel_for_index(std::size_t n, std::size_t grain, Body&& body) {
    const int jobs = parallel_detail::current_jobs;
    Parallelism(jobs > 0 ? jobs : default_jobs()).for_each_index(n, grain, std::forward<Body>(body));
}

#else

class Parallelism {
  public:
    /// jobs <= 0 means all cores.
    explicit Parallelism(int jobs)
        : jobs_(jobs > 0 ? jobs : default_jobs()),
          limit_(oneapi::tbb::global_control::max_allowed_parallelism, std::size_t(jobs_)),
          stack_(oneapi::tbb::global_control::thread_stack_size, kWorkerStackBytes),
          arena_(jobs_) {}

    /// The stack of oneTBB's worker threads (its default: 4 MiB). The recursive baseline
    /// recurses once per bounce, up to depth 256; under AddressSanitizer its frames are several
    /// times larger and 256 bounces overflowed 4 MiB. Reserved address space, not memory: pages
    /// are committed only as deep as a thread goes. oneTBB reads it when it starts its workers,
    /// which the first Parallelism of a process does.
    static constexpr std::size_t kWorkerStackBytes = std::size_t(64) << 20;

    int jobs() const { return jobs_; }

    /// Runs f() inside this arena, so the loops it calls (parallel_for_index,
    /// parallel_invoke) use at most jobs() threads; returns what f returns.
    template <class F>
    decltype(auto) run(F&& f) {
        return arena_.execute(std::forward<F>(f));
    }

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
                    ThreadProbe::note();
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
                                          ThreadProbe::note();
                                          for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                                      });
        });
    }

  private:
    int jobs_;
    oneapi::tbb::global_control limit_;
    oneapi::tbb::global_control stack_;
    oneapi::tbb::task_arena arena_;
};

/// Runs a() and b() possibly in parallel, in the caller's arena (so inside a Parallelism's
/// work, or after one was made, -j is honoured). For recursive builds (engine/accel).
template <class A, class B>
inline void parallel_invoke(A&& a, B&& b) {
    oneapi::tbb::parallel_invoke(
        [&] {
            ThreadProbe::note();
            a();
        },
        [&] {
            ThreadProbe::note();
            b();
        });
}

/// body(i) for i in [0, n), chunks of `grain`, in the caller's arena (see parallel_invoke).
template <class Body>
inline void parallel_for_index(std::size_t n, std::size_t grain, Body&& body) {
    oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, n, grain),
                              [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                                  ThreadProbe::note();
                                  for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                              });
}

#endif  // STREAMRT_STD_THREADS

}  // namespace streamrt
