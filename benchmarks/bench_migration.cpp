// Migration traffic of a redistribution against the tets that changed owner or halo: a slab of
// growing length with a post sliding over it, redistributed after each slide, once with
// incremental cycles (the default) and once with full ones (parallel.migration: full).
//   mpiexec -n 4 --oversubscribe build/benchmarks/bench_migration [out.csv]
// Per case and cycle: copies sent and dropped (all ranks), bytes of rows sent (all ranks), and
// the cycle's seconds (slowest rank, wall clock).  Bytes of rows are counted by the distribution
// (DistributionReport); the claims, drops and ghost requests that also travel are not in them
// (the PMPI interposer's redistribution phase counts everything: docs/parallel.md).
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "core/model_builder.hpp"
#include "drivers/scene_builders.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"

using namespace fdem;

namespace {

// A slab `length` m long (8 cells per m) with a post on it near x = 0.
Model slab_and_post(double length) {
  Scene scene = builders::basic_scene(1.0);
  scene.materials = {builders::elastic_material(1000, 1e6, 0.3)};
  const int cells = static_cast<int>(std::lround(8 * length));
  scene.bodies = {builders::box_body("slab", {0, 0, 0}, {length, 0.6, 0.2}, cells, 5, 2, 0),
                  builders::box_body("post", {0.2, 0.2, 0.21}, {0.4, 0.4, 1.0}, 2, 2, 6, 0)};
  return build_model(scene, load_body_meshes(scene));
}

void slide_post(Model& model, double shift) {
  NodeArrays& n = model.nodes;
  for (LocalIndex i = 0; i < n.size(); ++i)
    if (n.x0(i)[2] > 0.205) n.x[3 * i] += shift;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  {
    const Communicator comm = Communicator::world();
    const std::string csv = argc > 1 ? argv[1] : "bench_migration.csv";
    std::ofstream out;
    if (comm.is_root()) {
      out.open(csv);
      out << "mode,ranks,tets,shift_m,cycle,sent_copies,dropped_copies,sent_bytes,seconds\n";
      std::printf("%-12s %5s %7s %6s %5s %8s %8s %10s %9s\n", "mode", "ranks", "tets", "shift",
                  "cycle", "sent", "dropped", "bytes", "ms");
    }
    for (double length : {4.0, 8.0, 16.0})
      for (double shift : {0.0, 0.3, 0.9})
        for (bool incremental : {true, false}) {
          const Model global = slab_and_post(length);
          DistributionSettings settings;
          settings.incremental = incremental;
          TravellingState whole, state;
          whole.x_at_detection = global.nodes.x;
          Model local;
          Distribution d(comm, settings, global, whole, 0.02, {}, local, state);
          for (int cycle = 1; cycle <= 4; ++cycle) {
            slide_post(local, shift);
            state.x_at_detection = local.nodes.x;
            comm.barrier();
            const double t0 = MPI_Wtime();
            d.redistribute(local, state, {}, 0.0);
            const double seconds = comm.max(MPI_Wtime() - t0);
            const DistributionReport& r = d.report();
            if (!comm.is_root()) continue;
            const char* mode = incremental ? "incremental" : "full";
            out << mode << ',' << comm.size() << ',' << global.tets.size() << ',' << shift << ','
                << cycle << ',' << r.last_sent_tets << ',' << r.last_dropped_tets << ','
                << r.last_sent_bytes << ',' << seconds << '\n';
            std::printf("%-12s %5d %7ld %6.2f %5d %8ld %8ld %10ld %9.3f\n", mode, comm.size(),
                        static_cast<long>(global.tets.size()), shift, cycle, r.last_sent_tets,
                        r.last_dropped_tets, r.last_sent_bytes, 1e3 * seconds);
          }
        }
    if (comm.is_root()) std::printf("wrote %s\n", csv.c_str());
  }
  MPI_Finalize();
  return 0;
}
