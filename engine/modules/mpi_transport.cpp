// libstreamrt_mpi.so: MPI behind the plain table of distributed/mpi_transport.h, loaded by
// distributed/mpi_render.cpp for --mpi only. The C API of Debian's Open MPI or MPICH.
#include <mpi.h>

#include "distributed/mpi_transport.h"

namespace {

bool init(int* argc, char*** argv, int* rank, int* size) {
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    return provided >= MPI_THREAD_FUNNELED;
}

void finalize() { MPI_Finalize(); }

void abort_all(int code) { MPI_Abort(MPI_COMM_WORLD, code); }

void broadcast(void* data, int bytes, int root) { MPI_Bcast(data, bytes, MPI_BYTE, root, MPI_COMM_WORLD); }

int min_over_ranks(int value) {
    int out = value;
    MPI_Allreduce(&value, &out, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return out;
}

void* start_send(const void* data, int bytes, int dest, int tag) {
    auto* request = new MPI_Request;
    MPI_Isend(data, bytes, MPI_BYTE, dest, tag, MPI_COMM_WORLD, request);
    return request;
}

bool test(void* send) {
    auto* request = static_cast<MPI_Request*>(send);
    int done = 0;
    MPI_Test(request, &done, MPI_STATUS_IGNORE);
    if (done) delete request;
    return done != 0;
}

bool probe(int source, int tag, int* from, int* bytes) {
    MPI_Status status;
    int flag = 0;
    MPI_Iprobe(source == streamrt::kAnySource ? MPI_ANY_SOURCE : source, tag, MPI_COMM_WORLD, &flag, &status);
    if (!flag) return false;
    *from = status.MPI_SOURCE;
    MPI_Get_count(&status, MPI_BYTE, bytes);
    return true;
}

void receive(void* data, int bytes, int source, int tag) {
    MPI_Recv(data, bytes, MPI_BYTE, source, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

constexpr streamrt::MpiTransport kTransport{streamrt::kMpiTransportVersion,
                                            &init,
                                            &finalize,
                                            &abort_all,
                                            &broadcast,
                                            &min_over_ranks,
                                            &start_send,
                                            &test,
                                            &probe,
                                            &receive};

}  // namespace

extern "C" __attribute__((visibility("default"))) const streamrt::MpiTransport* streamrt_mpi_transport() {
    return &kTransport;
}
