#pragma once
// Rendering one image with the ranks of an MPI job (streamrt --mpi; docs/distributed.md).
// Only the main thread calls MPI (MPI_THREAD_FUNNELED); every rank renders with its own
// threads; rank 0 hands out tiles from one list in a fixed order and places the tiles that
// come back, so the picture is the single-process picture, byte for byte.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "distributed/scene_bundle.h"
#include "driver/render.h"
#include "stream/profile.h"

namespace streamrt {

/// True when the MPI module loads (built when CMake finds MPI: option STREAMRT_MPI); else
/// `why` (when given) says where it was looked for.
bool mpi_available(std::string* why = nullptr);

/// The environment variable showing that an MPI launcher (mpirun, mpiexec, srun --mpi)
/// started this process as one of several ranks, or nullptr.
const char* mpi_launcher_variable();

/// What one rank did, for --profile.
struct RankStats {
    int rank = 0;
    std::uint64_t tiles = 0;
    double busy_seconds = 0;  ///< rendering
    double idle_seconds = 0;  ///< waiting for work or for the others
    std::uint64_t bytes_sent = 0;
};

struct MpiTransport;

/// Loads the MPI module (libstreamrt_mpi.so, distributed/mpi_transport.h), MPI_Init_thread
/// (FUNNELED) on construction, MPI_Finalize on destruction; throws UsageError when the
/// module is missing (MPI not built in); ends the job when the thread level is not provided.
class MpiSession {
  public:
    MpiSession(int& argc, char**& argv);
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    int rank() const { return rank_; }
    int size() const { return size_; }

    /// Rank 0 tells every rank a status (0: go on); the others receive it.
    int broadcast_status(int status) const;
    /// Rank 0 sends the scene's bytes to every rank; the others receive them.
    void broadcast_bundle(SceneBundle& bundle) const;
    /// The lowest value over all ranks.
    int min_over_ranks(int value) const;
    /// Ends the whole job now with `code` (a rank failed or was interrupted).
    [[noreturn]] void abort(int code) const;
    const MpiTransport& transport() const { return *mpi_; }

  private:
    const MpiTransport* mpi_ = nullptr;
    int rank_ = 0, size_ = 1;
};

enum class MpiSchedule { Dynamic, Static };

/// Renders `tiles` (rank 0's list, in this order; other ranks pass an empty one) over all
/// ranks. On rank 0, every finished tile, its own and the others', goes to `sink` and counts
/// in `progress`; `profile` (rank 0) receives every rank's stage figures. Returns, on rank 0,
/// every rank's figures.
std::vector<RankStats> mpi_render_tiles(const MpiSession& mpi, PreparedRender& prepared, Parallelism& par,
                                        std::span<const int> tiles, MpiSchedule schedule, const TileSink& sink,
                                        RenderProgress& progress, StreamProfile* profile);

/// The per-rank table of --profile.
std::string rank_stats_text(const std::vector<RankStats>& stats);

}  // namespace streamrt
