#include "distributed/mpi_render.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "core/error.h"
#include "core/module_loader.h"
#include "distributed/mpi_transport.h"
#include "distributed/tile_file.h"

namespace streamrt {

const char* mpi_launcher_variable() {
    // Open MPI (OMPI_COMM_WORLD_SIZE), MPICH/Hydra and Slurm's PMI-2 (PMI_SIZE): a size
    // above 1 means several copies of this program run now. PMIx (srun --mpi=pmix) names
    // the rank only.
    for (const char* size : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
        if (const char* v = std::getenv(size); v && std::atoi(v) > 1) return size;
    if (std::getenv("PMIX_RANK") && !std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMI_SIZE"))
        return "PMIX_RANK";
    return nullptr;
}

std::string rank_stats_text(const std::vector<RankStats>& stats) {
    std::string out = "rank  tiles   busy s   idle s   bytes sent\n";
    char line[160];
    for (const RankStats& s : stats) {
        std::snprintf(line, sizeof line, "%4d %6llu %8.3f %8.3f %12llu\n", s.rank,
                      static_cast<unsigned long long>(s.tiles), s.busy_seconds, s.idle_seconds,
                      static_cast<unsigned long long>(s.bytes_sent));
        out += line;
    }
    return out;
}

namespace {

/// The MPI module's table, loaded on first use; null with `error` set when it is missing.
const MpiTransport* load_transport(std::string* error) {
    // Global: Open MPI loads plugins of its own that look up its library's symbols.
    static const ModuleTable<MpiTransport> loaded =
        load_module_table<MpiTransport>(kMpiModuleFile, kMpiTransportSymbol, kMpiTransportVersion, true);
    if (error) *error = loaded.error;
    return loaded.table;
}

}  // namespace

bool mpi_available(std::string* why) { return load_transport(why) != nullptr; }

namespace {

constexpr int kTagResult = 1;  // worker -> rank 0: int32 jobs, then finished tile records
constexpr int kTagAssign = 2;  // rank 0 -> worker: int32 tile numbers; none: no more work
constexpr int kTagFinal = 3;   // worker -> rank 0: its figures (FinalMessage)

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct FinalMessage {
    RankStats stats;
    std::array<StageFigures, kStageCount> stages;
    RayCounts counts;
};

/// Receives a message of unknown length from `source` with `tag`, waiting for it without
/// spinning a core away from the render threads.
template <class T>
std::vector<T> receive(const MpiTransport& mpi, int source, int tag) {
    int from = 0, bytes = 0;
    while (!mpi.probe(source, tag, &from, &bytes)) std::this_thread::sleep_for(std::chrono::microseconds(100));
    std::vector<T> data(std::size_t(bytes) / sizeof(T));
    mpi.receive(data.data(), bytes, from, tag);
    return data;
}

/// Sends and waits quietly (as `receive`) until the data may be reused.
void send_bytes(const MpiTransport& mpi, const void* data, std::size_t bytes, int dest, int tag, std::uint64_t& sent) {
    void* request = mpi.start_send(data, int(bytes), dest, tag);
    while (!mpi.test(request)) std::this_thread::sleep_for(std::chrono::microseconds(100));
    sent += bytes;
}

/// Rank 0's hand-out of tiles from one list in a fixed order: dynamic (the next tiles of
/// the list, to whoever asks) or static (rank r gets list positions r, r + N, ...).
class TileQueue {
  public:
    TileQueue(std::span<const int> tiles, int ranks, MpiSchedule schedule)
        : tiles_(tiles), ranks_(ranks), schedule_(schedule), next_(std::size_t(ranks)) {
        for (int r = 0; r < ranks; ++r) next_[std::size_t(r)] = std::size_t(r);
    }
    /// Up to n tiles for `rank` (none: no more).
    std::vector<std::int32_t> take(int rank, std::size_t n) {
        std::lock_guard<std::mutex> lock(mutex_);
        std::vector<std::int32_t> out;
        if (schedule_ == MpiSchedule::Dynamic) {
            while (out.size() < n && cursor_ < tiles_.size()) out.push_back(tiles_[cursor_++]);
        } else {
            std::size_t& p = next_[std::size_t(rank)];
            for (; out.size() < n && p < tiles_.size(); p += std::size_t(ranks_)) out.push_back(tiles_[p]);
        }
        return out;
    }
    /// The size of a worker's next chunk: large while much is left (fewer messages), down to
    /// one tile per thread at the end (ranks finish together).
    std::size_t chunk(int jobs) const {
        std::lock_guard<std::mutex> lock(mutex_);
        const std::size_t left = tiles_.size() - std::min(cursor_, tiles_.size());
        const std::size_t j = std::size_t(std::max(1, jobs));
        if (schedule_ == MpiSchedule::Static) return 4 * j;
        return std::clamp(left / (2 * std::size_t(ranks_)), j, 8 * j);
    }

  private:
    std::span<const int> tiles_;
    int ranks_;
    MpiSchedule schedule_;
    std::size_t cursor_ = 0;
    std::vector<std::size_t> next_;
    mutable std::mutex mutex_;
};

std::vector<RankStats> render_as_rank0(const MpiSession& mpi, PreparedRender& prepared, Parallelism& par,
                                       std::span<const int> tiles, MpiSchedule schedule, const TileSink& sink,
                                       RenderProgress& progress, StreamProfile* profile) {
    const auto start = Clock::now();
    TileQueue queue(tiles, mpi.size(), schedule);
    std::vector<RankStats> stats(std::size_t(mpi.size()));
    for (int r = 0; r < mpi.size(); ++r) stats[std::size_t(r)].rank = r;
    RankStats& mine = stats[0];
    // Rank 0's threads take one tile at a time from the same queue, on a thread of their
    // own: the main thread stays free for MPI (MPI_THREAD_FUNNELED).
    std::atomic<bool> local_done{false};
    std::thread local([&] {
        const auto t0 = Clock::now();
        std::atomic<std::uint64_t> count{0};
        render_tiles(
            prepared, par,
            [&] {
                const auto t = queue.take(0, 1);
                return t.empty() ? -1 : t[0];
            },
            [&](const TileOutput& t) {
                sink(t);
                ++count;
            },
            &progress);
        mine.busy_seconds = since(t0);
        mine.tiles = count.load();
        local_done = true;
    });
    int working = mpi.size() - 1;
    // Tiles handed to each worker and not yet back: a worker that gets "no more" while it
    // still renders some sends them with one more request, and is done once it has none.
    std::vector<std::uint64_t> out(std::size_t(mpi.size()), 0);
    while (working > 0) {
        int from = 0, bytes = 0;
        if (!mpi.transport().probe(kAnySource, kTagResult, &from, &bytes)) {
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        const std::vector<char> msg = receive<char>(mpi.transport(), from, kTagResult);
        std::int32_t jobs = 1;
        std::memcpy(&jobs, msg.data(), sizeof jobs);
        // A rank that was interrupted (its own Ctrl-C or SIGTERM) stops the whole job.
        if (jobs <= 0 && progress.cancel) progress.cancel->store(true);
        const std::string_view records(msg.data() + sizeof jobs, msg.size() - sizeof jobs);
        RankStats& theirs = stats[std::size_t(from)];
        read_tile_records(records, prepared.width, prepared.height, [&](const TileOutput& t) {
            sink(t);
            progress.add(t.counts);
            ++theirs.tiles;
            --out[std::size_t(from)];
        });
        // Once interrupted, every rank is told "no more" and the job winds down together.
        const std::vector<std::int32_t> chunk =
            progress.cancelled() ? std::vector<std::int32_t>() : queue.take(from, queue.chunk(jobs));
        send_bytes(mpi.transport(), chunk.data(), chunk.size() * sizeof(std::int32_t), from, kTagAssign, mine.bytes_sent);
        out[std::size_t(from)] += chunk.size();
        // An interrupted worker renders nothing more: it is done whatever it still had.
        if (chunk.empty() && (out[std::size_t(from)] == 0 || jobs <= 0)) --working;
    }
    local.join();
    for (int r = 1; r < mpi.size(); ++r) {
        const std::vector<FinalMessage> f = receive<FinalMessage>(mpi.transport(), r, kTagFinal);
        const std::uint64_t tiles_seen = stats[std::size_t(r)].tiles;
        stats[std::size_t(r)] = f.at(0).stats;
        stats[std::size_t(r)].tiles = tiles_seen;
        if (profile) {
            for (int s = 0; s < kStageCount; ++s) profile->stages[std::size_t(s)] += f[0].stages[std::size_t(s)];
            profile->counts += f[0].counts;
        }
    }
    // The per-generation rows are not sent between ranks: rank 0's alone would not add up
    // to the stage table, so with more than one rank there are none.
    if (profile && mpi.size() > 1) profile->generations.clear();
    mine.idle_seconds = std::max(0.0, since(start) - mine.busy_seconds);
    if (profile) profile->wall_seconds = since(start);
    return stats;
}

/// A worker's tiles between rank 0 and its render threads: the threads take them one at a
/// time (blocking while none is queued) and append each finished tile's record to a buffer;
/// the main thread pushes chunks in and sends the records out (it alone calls MPI).
class LocalTiles {
  public:
    /// The next tile to render; waits while none is queued; negative: closed.
    int take() {
        std::unique_lock<std::mutex> lock(mutex_);
        threads_wake_.wait(lock, [&] { return !tiles_.empty() || closed_; });
        if (tiles_.empty()) return -1;
        const int tile = tiles_.front();
        tiles_.pop_front();
        ++rendering_;
        main_wake_.notify_one();
        return tile;
    }
    void finished(const TileOutput& t) {
        std::lock_guard<std::mutex> lock(mutex_);
        append_tile_record(records_, t);
        ++record_count_;
        --rendering_;
        if (tiles_.empty() && rendering_ == 0) {
            busy_seconds_ += since(busy_since_);
            main_wake_.notify_one();
        }
    }
    void push(const std::vector<std::int32_t>& chunk) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (tiles_.empty() && rendering_ == 0) busy_since_ = Clock::now();
        tiles_.insert(tiles_.end(), chunk.begin(), chunk.end());
        threads_wake_.notify_all();
    }
    /// Stops the render threads once the queue is empty (at once when cancelled: they
    /// check the flag before each tile).
    void close() {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
        threads_wake_.notify_all();
    }
    /// Waits (checking `stop` now and then) until fewer than `queued` tiles wait to be
    /// started, or, with `queued` 0, until every tile is rendered.
    void wait_below(std::size_t queued, const std::function<bool()>& stop) {
        std::unique_lock<std::mutex> lock(mutex_);
        const auto ready = [&] { return queued > 0 ? tiles_.size() < queued : tiles_.empty() && rendering_ == 0; };
        while (!ready() && !stop()) main_wake_.wait_for(lock, std::chrono::milliseconds(20));
    }
    /// The records finished since the last call, and how many tiles they hold.
    std::pair<std::string, std::int64_t> take_records() {
        std::lock_guard<std::mutex> lock(mutex_);
        std::pair<std::string, std::int64_t> out{std::move(records_), record_count_};
        records_.clear();
        record_count_ = 0;
        return out;
    }
    double busy_seconds() {
        std::lock_guard<std::mutex> lock(mutex_);
        return busy_seconds_ + (tiles_.empty() && rendering_ == 0 ? 0.0 : since(busy_since_));
    }

  private:
    std::mutex mutex_;
    std::condition_variable threads_wake_, main_wake_;
    std::deque<int> tiles_;
    int rendering_ = 0;  ///< tiles taken, not finished
    bool closed_ = false;
    std::string records_;
    std::int64_t record_count_ = 0;
    Clock::time_point busy_since_{};
    double busy_seconds_ = 0;  ///< time with tiles queued or rendering
};

/// A worker: its render threads take tiles one at a time from a local queue, and the main
/// thread asks rank 0 for the next chunk (sending the tiles finished so far) as soon as fewer
/// than one tile per thread waits to be started, so the threads never wait for the slowest
/// tile of a chunk or for the round trip. An empty reply while tiles are still out: the
/// worker finishes them and sends them with one more request; rank 0 lets a worker go once
/// it has every tile back (or the worker was interrupted).
void render_as_worker(const MpiSession& mpi, PreparedRender& prepared, Parallelism& par, RenderProgress& progress,
                      StreamProfile* profile) {
    const auto start = Clock::now();
    FinalMessage final{};
    final.stats.rank = mpi.rank();
    const std::int32_t jobs = par.jobs();
    LocalTiles local;
    std::thread render([&] {
        render_tiles(prepared, par, [&] { return local.take(); }, [&](const TileOutput& t) { local.finished(t); },
                     &progress);
    });
    std::int64_t out = 0;  // tiles received from rank 0 and not yet sent back
    bool draining = false;  // rank 0 has no more: finish the tiles here, then send them
    for (;;) {
        local.wait_below(draining ? 0 : std::size_t(jobs), [&] { return progress.cancelled(); });
        auto [msg, count] = local.take_records();
        out -= count;
        const std::int32_t asking = progress.cancelled() ? 0 : jobs;  // 0: interrupted
        msg.insert(0, reinterpret_cast<const char*>(&asking), sizeof asking);
        send_bytes(mpi.transport(), msg.data(), msg.size(), 0, kTagResult, final.stats.bytes_sent);
        const std::vector<std::int32_t> chunk = receive<std::int32_t>(mpi.transport(), 0, kTagAssign);
        if (chunk.empty()) {
            if (out == 0 || asking == 0) break;
            draining = true;
            continue;
        }
        out += std::int64_t(chunk.size());
        local.push(chunk);
    }
    local.close();
    render.join();
    final.stats.busy_seconds = local.busy_seconds();
    final.stats.idle_seconds = std::max(0.0, since(start) - final.stats.busy_seconds);
    final.stats.tiles = std::uint64_t(progress.tiles_done.load());
    if (profile) {
        final.stages = profile->stages;
        final.counts = profile->counts;
    }
    std::uint64_t ignored = 0;
    send_bytes(mpi.transport(), &final, sizeof final, 0, kTagFinal, ignored);
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
    std::string error;
    mpi_ = load_transport(&error);
    if (!mpi_) throw UsageError("--mpi: this streamrt has no MPI support (" + error + "; cmake -DSTREAMRT_MPI=ON)");
    if (!mpi_->init(&argc, &argv, &rank_, &size_)) {
        if (rank_ == 0) std::fprintf(stderr, "streamrt: --mpi: the MPI library does not provide MPI_THREAD_FUNNELED\n");
        abort(2);
    }
}

MpiSession::~MpiSession() { mpi_->finalize(); }

int MpiSession::broadcast_status(int status) const {
    mpi_->broadcast(&status, sizeof status, 0);
    return status;
}

void MpiSession::broadcast_bundle(SceneBundle& bundle) const {
    std::string bytes = rank_ == 0 ? bundle.serialize() : std::string();
    std::uint64_t size = bytes.size();
    mpi_->broadcast(&size, sizeof size, 0);
    bytes.resize(size);
    // In pieces below 2 GiB (MPI counts are int).
    constexpr std::uint64_t kPiece = 1u << 30;
    for (std::uint64_t off = 0; off < size; off += kPiece)
        mpi_->broadcast(bytes.data() + off, int(std::min(kPiece, size - off)), 0);
    if (rank_ != 0) bundle = SceneBundle::deserialize(bytes);
}

int MpiSession::min_over_ranks(int value) const {
    return mpi_->min_over_ranks(value);
}

void MpiSession::abort(int code) const {
    std::fflush(stdout);
    std::fflush(stderr);
    mpi_->abort(code);
    std::_Exit(code);
}

std::vector<RankStats> mpi_render_tiles(const MpiSession& mpi, PreparedRender& prepared, Parallelism& par,
                                        std::span<const int> tiles, MpiSchedule schedule, const TileSink& sink,
                                        RenderProgress& progress, StreamProfile* profile) {
    if (mpi.rank() == 0) return render_as_rank0(mpi, prepared, par, tiles, schedule, sink, progress, profile);
    render_as_worker(mpi, prepared, par, progress, profile);
    return {};
}

}  // namespace streamrt
