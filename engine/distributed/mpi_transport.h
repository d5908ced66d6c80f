#pragma once
// The MPI module's table (engine/modules/mpi_transport.cpp, built as libstreamrt_mpi.so when
// MPI is found, and loaded by distributed/mpi_render.cpp only for --mpi): the few calls the
// tile hand-out needs, on MPI_COMM_WORLD, in plain types. Runs without --mpi do not load the
// MPI library and its dependencies at start-up.

namespace streamrt {

struct MpiTransport {
    int version;
    /// MPI_Init_thread asking for MPI_THREAD_FUNNELED; this rank and the number of ranks.
    /// False when the library provides less than FUNNELED.
    bool (*init)(int* argc, char*** argv, int* rank, int* size);
    void (*finalize)();
    void (*abort)(int code);
    /// MPI_Bcast of `bytes` bytes from rank `root`.
    void (*broadcast)(void* data, int bytes, int root);
    /// The lowest `value` over all ranks (MPI_Allreduce, MPI_MIN).
    int (*min_over_ranks)(int value);
    /// Starts sending `bytes` bytes; the handle is polled with `test` until it is done.
    void* (*start_send)(const void* data, int bytes, int dest, int tag);
    /// True once the send is done (the handle is then released).
    bool (*test)(void* send);
    /// Whether a message with `tag` from `source` (kAnySource: any rank) has arrived, and
    /// then its sender and size, without waiting.
    bool (*probe)(int source, int tag, int* from, int* bytes);
    /// Receives the message `probe` found.
    void (*receive)(void* data, int bytes, int source, int tag);
};

inline constexpr int kMpiTransportVersion = 1;
inline constexpr int kAnySource = -1;
inline constexpr const char* kMpiModuleFile = "libstreamrt_mpi.so";
inline constexpr const char* kMpiTransportSymbol = "streamrt_mpi_transport";

}  // namespace streamrt
