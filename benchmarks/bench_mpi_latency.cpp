// MPI latency and bandwidth on this machine, the inputs of the cost model (scripts/cost-model.py):
//   allreduce  MPI_Allreduce (sum of doubles) of 1 and 22 numbers (fdem's per-step reductions)
//   pingpong   MPI_Send/MPI_Recv round trip between ranks 0 and 1, half of it per message, for
//              8 B .. 4 MiB (latency = the small sizes, bandwidth = the large ones)
// Run on >= 2 ranks: mpiexec -n 2 build/benchmarks/bench_mpi_latency [out.csv]
// Prints one line per case and writes CSV: kind, ranks, bytes, seconds (per operation, median of
// 7 batches), bytes_per_second. Wall clock (MPI_Wtime): on a loaded machine the figures include
// time given to other processes.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <vector>

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <class Op>
double time_per_op(Op op, int reps) {
  std::vector<double> batches;
  for (int b = 0; b < 7; ++b) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    for (int i = 0; i < reps; ++i) op();
    double t = (MPI_Wtime() - t0) / reps;
    MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    batches.push_back(t);
  }
  return median(batches);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::FILE* csv = nullptr;
  if (rank == 0) {
    csv = std::fopen(argc > 1 ? argv[1] : "bench_mpi_latency.csv", "w");
    if (csv) std::fprintf(csv, "kind,ranks,bytes,seconds,bytes_per_second\n");
  }
  auto report = [&](const char* kind, long bytes, double s) {
    if (rank != 0) return;
    std::printf("%-10s ranks %d %9ld B  %10.3f us  %9.3f MB/s\n", kind, ranks, bytes, s * 1e6,
                bytes / s / 1e6);
    if (csv) std::fprintf(csv, "%s,%d,%ld,%.9g,%.6g\n", kind, ranks, bytes, s, bytes / s);
  };
  for (int n : {1, 22}) {
    std::vector<double> in(n, 1.0), out(n);
    const double s = time_per_op(
        [&] { MPI_Allreduce(in.data(), out.data(), n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD); },
        2000);
    report("allreduce", 8L * n, s);
  }
  if (ranks >= 2) {
    for (long bytes = 8; bytes <= (4L << 20); bytes *= 8) {
      std::vector<char> buf(bytes);
      const int reps = bytes < 65536 ? 2000 : 50;
      const double s = time_per_op(
          [&] {
            if (rank == 0) {
              MPI_Send(buf.data(), (int)bytes, MPI_CHAR, 1, 0, MPI_COMM_WORLD);
              MPI_Recv(buf.data(), (int)bytes, MPI_CHAR, 1, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            } else if (rank == 1) {
              MPI_Recv(buf.data(), (int)bytes, MPI_CHAR, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
              MPI_Send(buf.data(), (int)bytes, MPI_CHAR, 0, 0, MPI_COMM_WORLD);
            }
          },
          reps);
      report("pingpong", bytes, s / 2);
    }
  }
  if (csv) std::fclose(csv);
  MPI_Finalize();
  return 0;
}
