// Communication-budget interposer: a PMPI library preloaded into the fdem command
// (LD_PRELOAD=libfdem_comm_budget.so) that counts, per rank and per run phase, the bytes this rank
// RECEIVES, the calls, the point-to-point messages and the blocking collectives.  fdem marks its
// phases with MPI_Pcontrol(100 + phase) (parallel/communicator.hpp, CommPhase); calls before the
// first marker count in phase 0, "init".  At MPI_Finalize each rank writes
// ${FDEM_COMM_BUDGET_OUT}/rank<R>.json when FDEM_COMM_BUDGET_OUT is set (see docs/parallel.md,
// "Communication budget test").
//
// What counts as received: the bytes MPI delivers into this rank's receive buffers from OTHER
// ranks, as the application sees them (not the wire volume of the algorithm MPI picks):
// - Recv, Sendrecv(_replace), blocking file reads: the size in the returned status;
// - Irecv, non-blocking file reads and non-blocking collectives: the posted size (count × type
//   size), counted when posted, in the phase that posts them;
// - Bcast, Scatter(v): non-root ranks; Reduce: the root; Allreduce, Scan, Exscan: the result;
//   Allgather(v), Gather(v) at the root, Alltoall(v/w): every block except the rank's own;
//   Reduce_scatter(_block): this rank's block; Neighbor_*: one block per in-neighbour.
// - MPI_File_read*: bytes read from the file count as received (and as file_bytes_read).
// Data Open MPI moves inside its own components (OMPIO's collective buffering, coll algorithms)
// does not go through the PMPI layer and is not seen; the MPI calls HDF5 makes are.
// Not thread-safe: fdem calls MPI from one thread (MPI_THREAD_FUNNELED).
#define OMPI_SKIP_MPICXX 1
#include <mpi.h>

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

constexpr int kPhaseBase = 100;  // MPI_Pcontrol(100 + phase)
constexpr int kPhases = 16;      // 0 = init, 1..7 = CommPhase, the rest reserved
const char* const kPhaseNames[] = {"init",   "startup",    "step",    "redistribution",
                                   "output", "checkpoint", "restart", "finish"};
constexpr int kNamedPhases = sizeof(kPhaseNames) / sizeof(kPhaseNames[0]);

// clang-format off
#define FDEM_BUDGET_OPS(X)                                                                        \
  X(Recv) X(Irecv) X(Sendrecv) X(Sendrecv_replace) X(Bcast) X(Reduce) X(Allreduce) X(Scan)        \
  X(Exscan) X(Gather) X(Gatherv) X(Scatter) X(Scatterv) X(Allgather) X(Allgatherv) X(Alltoall)    \
  X(Alltoallv) X(Alltoallw) X(Reduce_scatter) X(Reduce_scatter_block) X(Barrier)                 \
  X(Neighbor_allgather) X(Neighbor_allgatherv) X(Neighbor_alltoall) X(Neighbor_alltoallv)         \
  X(Ibcast) X(Ireduce) X(Iallreduce) X(Iallgather) X(Iallgatherv) X(Ialltoall) X(Ialltoallv)      \
  X(Ibarrier) X(File_read) X(File_read_at) X(File_read_all) X(File_read_at_all)                   \
  X(File_read_shared) X(File_read_ordered) X(File_iread) X(File_iread_at) X(File_write)           \
  X(File_write_at) X(File_write_all) X(File_write_at_all)
// clang-format on

enum Op : int {
#define FDEM_BUDGET_ENUM(name) op_##name,
  FDEM_BUDGET_OPS(FDEM_BUDGET_ENUM)
#undef FDEM_BUDGET_ENUM
      op_count
};
const char* const kOpNames[] = {
#define FDEM_BUDGET_NAME(name) "MPI_" #name,
    FDEM_BUDGET_OPS(FDEM_BUDGET_NAME)
#undef FDEM_BUDGET_NAME
};

struct Counter {
  std::uint64_t bytes = 0;
  std::uint64_t calls = 0;
};

struct PhaseCounters {
  Counter by_op[op_count];
  std::uint64_t bytes_received = 0;
  std::uint64_t calls = 0;
  std::uint64_t p2p_messages = 0;  // point-to-point receives (Recv, Irecv, Sendrecv)
  std::uint64_t blocking_collectives = 0;
  std::uint64_t file_bytes_read = 0;
  std::uint64_t file_bytes_written = 0;
};

PhaseCounters g_phases[kPhases];
int g_phase = 0;

enum Kind { other = 0, p2p = 1, blocking_collective = 2, file_read = 4, file_write = 8 };

void record(Op op, std::uint64_t bytes, int kind) {
  PhaseCounters& p = g_phases[g_phase];
  p.by_op[op].bytes += bytes;
  p.by_op[op].calls += 1;
  p.calls += 1;
  if (kind & file_write) {
    p.file_bytes_written += bytes;
    return;  // written, not received
  }
  p.bytes_received += bytes;
  if (kind & p2p) p.p2p_messages += 1;
  if (kind & blocking_collective) p.blocking_collectives += 1;
  if (kind & file_read) p.file_bytes_read += bytes;
}

std::uint64_t type_size(MPI_Datatype type) {
  int size = 0;
  if (type == MPI_DATATYPE_NULL || PMPI_Type_size(type, &size) != MPI_SUCCESS) return 0;
  return static_cast<std::uint64_t>(size);
}
std::uint64_t bytes_of(std::int64_t count, MPI_Datatype type) {
  return count > 0 ? static_cast<std::uint64_t>(count) * type_size(type) : 0;
}
// Bytes a completed receive or file read delivered (posted size if the status says nothing).
std::uint64_t status_bytes(const MPI_Status* status, MPI_Datatype type, int posted) {
  int count = MPI_UNDEFINED;
  if (PMPI_Get_count(status, type, &count) != MPI_SUCCESS || count == MPI_UNDEFINED) count = posted;
  return bytes_of(count, type);
}
int rank_of(MPI_Comm comm) {
  int r = 0;
  PMPI_Comm_rank(comm, &r);
  return r;
}
int size_of(MPI_Comm comm) {
  int s = 1;
  PMPI_Comm_size(comm, &s);
  return s;
}
// Sum of the blocks from the other ranks (i ≠ this rank) of a v-collective.
std::uint64_t others_v(const int counts[], MPI_Datatype type, MPI_Comm comm) {
  const int n = size_of(comm), me = rank_of(comm);
  std::int64_t sum = 0;
  for (int i = 0; i < n; ++i)
    if (i != me) sum += counts[i];
  return bytes_of(sum, type);
}
// In-neighbours of a process topology (neighbourhood collectives).
int in_degree(MPI_Comm comm) {
  int topology = MPI_UNDEFINED;
  PMPI_Topo_test(comm, &topology);
  if (topology == MPI_DIST_GRAPH) {
    int in = 0, out = 0, weighted = 0;
    PMPI_Dist_graph_neighbors_count(comm, &in, &out, &weighted);
    return in;
  }
  if (topology == MPI_GRAPH) {
    int n = 0;
    PMPI_Graph_neighbors_count(comm, rank_of(comm), &n);
    return n;
  }
  if (topology == MPI_CART) {
    int dims = 0;
    PMPI_Cartdim_get(comm, &dims);
    return 2 * dims;
  }
  return 0;
}

// A call that completes a receive or a read: counts what its status says was delivered.
template <class Call>
int completed(Op op, int kind, MPI_Status* status, MPI_Datatype type, int count, Call call) {
  MPI_Status local;
  MPI_Status* st = status == MPI_STATUS_IGNORE ? &local : status;
  const int rc = call(st);
  record(op, rc == MPI_SUCCESS ? status_bytes(st, type, count) : 0, kind);
  return rc;
}

void write_json() {
  const char* dir = std::getenv("FDEM_COMM_BUDGET_OUT");
  if (dir == nullptr || *dir == '\0') return;
  const int rank = rank_of(MPI_COMM_WORLD), size = size_of(MPI_COMM_WORLD);
  const std::string path = std::string(dir) + "/rank" + std::to_string(rank) + ".json";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "comm budget: cannot write %s\n", path.c_str());
    return;
  }
  std::fprintf(f, "{\"rank\": %d, \"size\": %d, \"phases\": {", rank, size);
  bool first_phase = true;
  for (int ph = 0; ph < kPhases; ++ph) {
    const PhaseCounters& p = g_phases[ph];
    if (ph >= kNamedPhases && p.calls == 0) continue;
    const std::string name = ph < kNamedPhases ? kPhaseNames[ph] : "phase" + std::to_string(ph);
    std::fprintf(f,
                 "%s\n  \"%s\": {\"bytes_received\": %" PRIu64 ", \"calls\": %" PRIu64
                 ", \"p2p_messages\": %" PRIu64 ", \"blocking_collectives\": %" PRIu64
                 ", \"file_bytes_read\": %" PRIu64 ", \"file_bytes_written\": %" PRIu64
                 ", \"by_call\": {",
                 first_phase ? "" : ",", name.c_str(), p.bytes_received, p.calls, p.p2p_messages,
                 p.blocking_collectives, p.file_bytes_read, p.file_bytes_written);
    first_phase = false;
    bool first_op = true;
    for (int op = 0; op < op_count; ++op) {
      if (p.by_op[op].calls == 0) continue;
      std::fprintf(f, "%s\"%s\": {\"bytes\": %" PRIu64 ", \"calls\": %" PRIu64 "}",
                   first_op ? "" : ", ", kOpNames[op], p.by_op[op].bytes, p.by_op[op].calls);
      first_op = false;
    }
    std::fprintf(f, "}}");
  }
  std::fprintf(f, "\n}}\n");
  std::fclose(f);
}

}  // namespace

extern "C" {

// ---- phases and the end of the run

int MPI_Pcontrol(const int level, ...) {
  if (level >= kPhaseBase && level < kPhaseBase + kPhases) {
    g_phase = level - kPhaseBase;
    return MPI_SUCCESS;
  }
  return PMPI_Pcontrol(level);
}

int MPI_Finalize(void) {
  write_json();
  return PMPI_Finalize();
}

// ---- point to point

int MPI_Recv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm,
             MPI_Status* status) {
  return completed(op_Recv, p2p, status, type, count, [&](MPI_Status* st) {
    return PMPI_Recv(buf, count, type, source, tag, comm, st);
  });
}

int MPI_Irecv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm,
              MPI_Request* request) {
  record(op_Irecv, source == MPI_PROC_NULL ? 0 : bytes_of(count, type), p2p);
  return PMPI_Irecv(buf, count, type, source, tag, comm, request);
}

int MPI_Sendrecv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, int dest, int sendtag,
                 void* recvbuf, int recvcount, MPI_Datatype recvtype, int source, int recvtag,
                 MPI_Comm comm, MPI_Status* status) {
  return completed(op_Sendrecv, p2p, status, recvtype, recvcount, [&](MPI_Status* st) {
    return PMPI_Sendrecv(sendbuf, sendcount, sendtype, dest, sendtag, recvbuf, recvcount, recvtype,
                         source, recvtag, comm, st);
  });
}

int MPI_Sendrecv_replace(void* buf, int count, MPI_Datatype type, int dest, int sendtag, int source,
                         int recvtag, MPI_Comm comm, MPI_Status* status) {
  return completed(op_Sendrecv_replace, p2p, status, type, count, [&](MPI_Status* st) {
    return PMPI_Sendrecv_replace(buf, count, type, dest, sendtag, source, recvtag, comm, st);
  });
}

// ---- blocking collectives

int MPI_Barrier(MPI_Comm comm) {
  record(op_Barrier, 0, blocking_collective);
  return PMPI_Barrier(comm);
}

int MPI_Bcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm) {
  record(op_Bcast, rank_of(comm) == root ? 0 : bytes_of(count, type), blocking_collective);
  return PMPI_Bcast(buf, count, type, root, comm);
}

int MPI_Reduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
               int root, MPI_Comm comm) {
  record(op_Reduce, rank_of(comm) == root ? bytes_of(count, type) : 0, blocking_collective);
  return PMPI_Reduce(sendbuf, recvbuf, count, type, op, root, comm);
}

int MPI_Allreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
                  MPI_Comm comm) {
  record(op_Allreduce, bytes_of(count, type), blocking_collective);
  return PMPI_Allreduce(sendbuf, recvbuf, count, type, op, comm);
}

int MPI_Scan(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
             MPI_Comm comm) {
  record(op_Scan, bytes_of(count, type), blocking_collective);
  return PMPI_Scan(sendbuf, recvbuf, count, type, op, comm);
}

int MPI_Exscan(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
               MPI_Comm comm) {
  record(op_Exscan, rank_of(comm) == 0 ? 0 : bytes_of(count, type), blocking_collective);
  return PMPI_Exscan(sendbuf, recvbuf, count, type, op, comm);
}

int MPI_Gather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
               int recvcount, MPI_Datatype recvtype, int root, MPI_Comm comm) {
  const std::uint64_t b =
      rank_of(comm) == root ? bytes_of(std::int64_t{recvcount} * (size_of(comm) - 1), recvtype) : 0;
  record(op_Gather, b, blocking_collective);
  return PMPI_Gather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, root, comm);
}

int MPI_Gatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                const int recvcounts[], const int displs[], MPI_Datatype recvtype, int root,
                MPI_Comm comm) {
  record(op_Gatherv, rank_of(comm) == root ? others_v(recvcounts, recvtype, comm) : 0,
         blocking_collective);
  return PMPI_Gatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs, recvtype, root,
                      comm);
}

int MPI_Scatter(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                int recvcount, MPI_Datatype recvtype, int root, MPI_Comm comm) {
  record(op_Scatter, rank_of(comm) == root ? 0 : bytes_of(recvcount, recvtype),
         blocking_collective);
  return PMPI_Scatter(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, root, comm);
}

int MPI_Scatterv(const void* sendbuf, const int sendcounts[], const int displs[],
                 MPI_Datatype sendtype, void* recvbuf, int recvcount, MPI_Datatype recvtype,
                 int root, MPI_Comm comm) {
  record(op_Scatterv, rank_of(comm) == root ? 0 : bytes_of(recvcount, recvtype),
         blocking_collective);
  return PMPI_Scatterv(sendbuf, sendcounts, displs, sendtype, recvbuf, recvcount, recvtype, root,
                       comm);
}

int MPI_Allgather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                  int recvcount, MPI_Datatype recvtype, MPI_Comm comm) {
  record(op_Allgather, bytes_of(std::int64_t{recvcount} * (size_of(comm) - 1), recvtype),
         blocking_collective);
  return PMPI_Allgather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}

int MPI_Allgatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                   const int recvcounts[], const int displs[], MPI_Datatype recvtype,
                   MPI_Comm comm) {
  record(op_Allgatherv, others_v(recvcounts, recvtype, comm), blocking_collective);
  return PMPI_Allgatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs, recvtype, comm);
}

int MPI_Alltoall(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                 int recvcount, MPI_Datatype recvtype, MPI_Comm comm) {
  record(op_Alltoall, bytes_of(std::int64_t{recvcount} * (size_of(comm) - 1), recvtype),
         blocking_collective);
  return PMPI_Alltoall(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}

int MPI_Alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[],
                  MPI_Datatype sendtype, void* recvbuf, const int recvcounts[], const int rdispls[],
                  MPI_Datatype recvtype, MPI_Comm comm) {
  record(op_Alltoallv, others_v(recvcounts, recvtype, comm), blocking_collective);
  return PMPI_Alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls,
                        recvtype, comm);
}

int MPI_Alltoallw(const void* sendbuf, const int sendcounts[], const int sdispls[],
                  const MPI_Datatype sendtypes[], void* recvbuf, const int recvcounts[],
                  const int rdispls[], const MPI_Datatype recvtypes[], MPI_Comm comm) {
  const int n = size_of(comm), me = rank_of(comm);
  std::uint64_t b = 0;
  for (int i = 0; i < n; ++i)
    if (i != me) b += bytes_of(recvcounts[i], recvtypes[i]);
  record(op_Alltoallw, b, blocking_collective);
  return PMPI_Alltoallw(sendbuf, sendcounts, sdispls, sendtypes, recvbuf, recvcounts, rdispls,
                        recvtypes, comm);
}

int MPI_Reduce_scatter(const void* sendbuf, void* recvbuf, const int recvcounts[],
                       MPI_Datatype type, MPI_Op op, MPI_Comm comm) {
  record(op_Reduce_scatter, bytes_of(recvcounts[rank_of(comm)], type), blocking_collective);
  return PMPI_Reduce_scatter(sendbuf, recvbuf, recvcounts, type, op, comm);
}

int MPI_Reduce_scatter_block(const void* sendbuf, void* recvbuf, int recvcount, MPI_Datatype type,
                             MPI_Op op, MPI_Comm comm) {
  record(op_Reduce_scatter_block, bytes_of(recvcount, type), blocking_collective);
  return PMPI_Reduce_scatter_block(sendbuf, recvbuf, recvcount, type, op, comm);
}

int MPI_Neighbor_allgather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                           int recvcount, MPI_Datatype recvtype, MPI_Comm comm) {
  record(op_Neighbor_allgather, bytes_of(std::int64_t{recvcount} * in_degree(comm), recvtype),
         blocking_collective);
  return PMPI_Neighbor_allgather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}

int MPI_Neighbor_allgatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype,
                            void* recvbuf, const int recvcounts[], const int displs[],
                            MPI_Datatype recvtype, MPI_Comm comm) {
  std::int64_t sum = 0;
  for (int i = 0, n = in_degree(comm); i < n; ++i) sum += recvcounts[i];
  record(op_Neighbor_allgatherv, bytes_of(sum, recvtype), blocking_collective);
  return PMPI_Neighbor_allgatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs,
                                  recvtype, comm);
}

int MPI_Neighbor_alltoall(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                          int recvcount, MPI_Datatype recvtype, MPI_Comm comm) {
  record(op_Neighbor_alltoall, bytes_of(std::int64_t{recvcount} * in_degree(comm), recvtype),
         blocking_collective);
  return PMPI_Neighbor_alltoall(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm);
}

int MPI_Neighbor_alltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[],
                           MPI_Datatype sendtype, void* recvbuf, const int recvcounts[],
                           const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm) {
  std::int64_t sum = 0;
  for (int i = 0, n = in_degree(comm); i < n; ++i) sum += recvcounts[i];
  record(op_Neighbor_alltoallv, bytes_of(sum, recvtype), blocking_collective);
  return PMPI_Neighbor_alltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts,
                                 rdispls, recvtype, comm);
}

// ---- non-blocking collectives (counted when posted; not blocking)

int MPI_Ibarrier(MPI_Comm comm, MPI_Request* request) {
  record(op_Ibarrier, 0, other);
  return PMPI_Ibarrier(comm, request);
}

int MPI_Ibcast(void* buf, int count, MPI_Datatype type, int root, MPI_Comm comm,
               MPI_Request* request) {
  record(op_Ibcast, rank_of(comm) == root ? 0 : bytes_of(count, type), other);
  return PMPI_Ibcast(buf, count, type, root, comm, request);
}

int MPI_Ireduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
                int root, MPI_Comm comm, MPI_Request* request) {
  record(op_Ireduce, rank_of(comm) == root ? bytes_of(count, type) : 0, other);
  return PMPI_Ireduce(sendbuf, recvbuf, count, type, op, root, comm, request);
}

int MPI_Iallreduce(const void* sendbuf, void* recvbuf, int count, MPI_Datatype type, MPI_Op op,
                   MPI_Comm comm, MPI_Request* request) {
  record(op_Iallreduce, bytes_of(count, type), other);
  return PMPI_Iallreduce(sendbuf, recvbuf, count, type, op, comm, request);
}

int MPI_Iallgather(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                   int recvcount, MPI_Datatype recvtype, MPI_Comm comm, MPI_Request* request) {
  record(op_Iallgather, bytes_of(std::int64_t{recvcount} * (size_of(comm) - 1), recvtype), other);
  return PMPI_Iallgather(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm, request);
}

int MPI_Iallgatherv(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                    const int recvcounts[], const int displs[], MPI_Datatype recvtype,
                    MPI_Comm comm, MPI_Request* request) {
  record(op_Iallgatherv, others_v(recvcounts, recvtype, comm), other);
  return PMPI_Iallgatherv(sendbuf, sendcount, sendtype, recvbuf, recvcounts, displs, recvtype, comm,
                          request);
}

int MPI_Ialltoall(const void* sendbuf, int sendcount, MPI_Datatype sendtype, void* recvbuf,
                  int recvcount, MPI_Datatype recvtype, MPI_Comm comm, MPI_Request* request) {
  record(op_Ialltoall, bytes_of(std::int64_t{recvcount} * (size_of(comm) - 1), recvtype), other);
  return PMPI_Ialltoall(sendbuf, sendcount, sendtype, recvbuf, recvcount, recvtype, comm, request);
}

int MPI_Ialltoallv(const void* sendbuf, const int sendcounts[], const int sdispls[],
                   MPI_Datatype sendtype, void* recvbuf, const int recvcounts[],
                   const int rdispls[], MPI_Datatype recvtype, MPI_Comm comm,
                   MPI_Request* request) {
  record(op_Ialltoallv, others_v(recvcounts, recvtype, comm), other);
  return PMPI_Ialltoallv(sendbuf, sendcounts, sdispls, sendtype, recvbuf, recvcounts, rdispls,
                         recvtype, comm, request);
}

// ---- MPI-IO (HDF5 checkpoints): reads count as received, writes separately

int MPI_File_read(MPI_File fh, void* buf, int count, MPI_Datatype type, MPI_Status* status) {
  return completed(op_File_read, file_read, status, type, count,
                   [&](MPI_Status* st) { return PMPI_File_read(fh, buf, count, type, st); });
}

int MPI_File_read_at(MPI_File fh, MPI_Offset offset, void* buf, int count, MPI_Datatype type,
                     MPI_Status* status) {
  return completed(op_File_read_at, file_read, status, type, count, [&](MPI_Status* st) {
    return PMPI_File_read_at(fh, offset, buf, count, type, st);
  });
}

int MPI_File_read_all(MPI_File fh, void* buf, int count, MPI_Datatype type, MPI_Status* status) {
  return completed(op_File_read_all, file_read | blocking_collective, status, type, count,
                   [&](MPI_Status* st) { return PMPI_File_read_all(fh, buf, count, type, st); });
}

int MPI_File_read_at_all(MPI_File fh, MPI_Offset offset, void* buf, int count, MPI_Datatype type,
                         MPI_Status* status) {
  return completed(
      op_File_read_at_all, file_read | blocking_collective, status, type, count,
      [&](MPI_Status* st) { return PMPI_File_read_at_all(fh, offset, buf, count, type, st); });
}

int MPI_File_read_shared(MPI_File fh, void* buf, int count, MPI_Datatype type, MPI_Status* status) {
  return completed(op_File_read_shared, file_read, status, type, count,
                   [&](MPI_Status* st) { return PMPI_File_read_shared(fh, buf, count, type, st); });
}

int MPI_File_read_ordered(MPI_File fh, void* buf, int count, MPI_Datatype type,
                          MPI_Status* status) {
  return completed(
      op_File_read_ordered, file_read | blocking_collective, status, type, count,
      [&](MPI_Status* st) { return PMPI_File_read_ordered(fh, buf, count, type, st); });
}

int MPI_File_iread(MPI_File fh, void* buf, int count, MPI_Datatype type, MPI_Request* request) {
  record(op_File_iread, bytes_of(count, type), file_read);
  return PMPI_File_iread(fh, buf, count, type, request);
}

int MPI_File_iread_at(MPI_File fh, MPI_Offset offset, void* buf, int count, MPI_Datatype type,
                      MPI_Request* request) {
  record(op_File_iread_at, bytes_of(count, type), file_read);
  return PMPI_File_iread_at(fh, offset, buf, count, type, request);
}

int MPI_File_write(MPI_File fh, const void* buf, int count, MPI_Datatype type, MPI_Status* status) {
  record(op_File_write, bytes_of(count, type), file_write);
  return PMPI_File_write(fh, buf, count, type, status);
}

int MPI_File_write_at(MPI_File fh, MPI_Offset offset, const void* buf, int count, MPI_Datatype type,
                      MPI_Status* status) {
  record(op_File_write_at, bytes_of(count, type), file_write);
  return PMPI_File_write_at(fh, offset, buf, count, type, status);
}

int MPI_File_write_all(MPI_File fh, const void* buf, int count, MPI_Datatype type,
                       MPI_Status* status) {
  record(op_File_write_all, bytes_of(count, type), file_write);
  g_phases[g_phase].blocking_collectives += 1;
  return PMPI_File_write_all(fh, buf, count, type, status);
}

int MPI_File_write_at_all(MPI_File fh, MPI_Offset offset, const void* buf, int count,
                          MPI_Datatype type, MPI_Status* status) {
  record(op_File_write_at_all, bytes_of(count, type), file_write);
  g_phases[g_phase].blocking_collectives += 1;
  return PMPI_File_write_at_all(fh, offset, buf, count, type, status);
}

}  // extern "C"
