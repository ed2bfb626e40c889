// Throughput of the element stages of a step on one core, against memory bandwidth:
//   forces     compute_internal_forces (the internal-force stage: per-tet forces added to the
//              nodes in ascending tet gid)
//   integrate  integrate_central_difference (per node; reported per tet of the same mesh)
// for box meshes of ~1e4, 1e5, 1e6 tets (6 per cell), three element orders (space-filling curve,
// the generator's lexicographic order, a random permutation of tets and nodes) and both elastic
// laws.  A STREAM-triad loop in the same run gives the bandwidth each stage is compared with.
//
// Usage: bench_internal_forces [out.csv] [--csv PATH] [--sizes 1e4,1e5,...] [--no-1e6]
//                              [--orders sfc,as_generated,random] [--min-time SECONDS]
//                              [--stream-mb MB] [--wall]
//   defaults: bench_internal_forces.csv, sizes 1e4,1e5,1e6, all three orders, 0.5 s per
//   measurement (best and median of ≥ 3 batches), triad on 3 × 80 MB, thread CPU time.
//   Ratios ("vs sfc") are to the sfc neo-Hookean result of the same stage and size, so they are
//   only printed when sfc is among the orders.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/dynamics.hpp"
#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"

using namespace fdem;

namespace {

// Timer: CPU time of this thread by default, so that time the scheduler gives to other processes
// on a shared machine is not counted (their cache and memory traffic still is); --wall for
// wall-clock time.
bool use_wall_clock = false;

double now_seconds() {
  timespec ts;
  clock_gettime(use_wall_clock ? CLOCK_MONOTONIC : CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double seconds_since(double start) {
  return now_seconds() - start;
}

struct Timing {
  double best = 0.0;    // s per call, fastest batch
  double median = 0.0;  // s per call, median batch
};

// Calls `step` in batches of equal size (each batch ≥ min_seconds / 5) until at least
// min_seconds have passed and at least 3 batches ran.
template <class Step>
Timing time_per_call(Step&& step, double min_seconds) {
  step();  // warm caches and page in buffers
  const double batch_target = min_seconds / 5.0;
  long calls = 1;
  std::vector<double> per_call;
  double total = 0.0;
  for (;;) {
    const double start = now_seconds();
    for (long i = 0; i < calls; ++i) step();
    const double t = seconds_since(start);
    total += t;
    if (t >= batch_target) {
      per_call.push_back(t / static_cast<double>(calls));
      break;
    }
    calls = std::max(2 * calls, static_cast<long>(calls * batch_target / std::max(t, 1e-9)));
  }
  while (total < min_seconds || per_call.size() < 3) {
    const double start = now_seconds();
    for (long i = 0; i < calls; ++i) step();
    const double t = seconds_since(start);
    total += t;
    per_call.push_back(t / static_cast<double>(calls));
  }
  std::sort(per_call.begin(), per_call.end());
  return {per_call.front(), per_call[per_call.size() / 2]};
}

// STREAM triad a = b + s·c over three arrays of `megabytes` each; best of `repeats`, in GB/s
// counted as STREAM does (24 bytes per element: two reads and one write, no write-allocate).
double triad_bandwidth(double megabytes, int repeats) {
  const std::size_t n = static_cast<std::size_t>(megabytes * 1e6 / sizeof(double));
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const double start = now_seconds();
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    best = std::min(best, seconds_since(start));
  }
  volatile double keep = a[n / 2];
  (void)keep;
  return 24.0 * static_cast<double>(n) / best / 1e9;
}

enum class Order { sfc, as_generated, random };
const char* order_name(Order o) {
  return o == Order::sfc ? "sfc" : o == Order::as_generated ? "as_generated" : "random";
}
const char* material_name(ElasticModel m) {
  return m == ElasticModel::neo_hookean ? "neo_hookean" : "st_venant_kirchhoff";
}

// Unit box (1 m × 1 m × 1 m) of n³ cells, rock-like elastic material (E = 10 GPa), undamped
// (viscosity 0, so the kernel neither reads velocities nor evaluates the viscous stress).
Scene box_scene(int cells, ElasticModel law) {
  Scene scene;
  scene.name = "bench_internal_forces";
  scene.source_path = "bench_internal_forces";
  scene.time.end = 1.0;
  MaterialSpec m;
  m.name = "rock";
  m.density = 2700.0;
  m.elastic.model = law;
  m.elastic.young = 10e9;
  m.elastic.poisson = 0.25;
  scene.materials.push_back(m);
  BodySpec b;
  b.name = "box";
  b.material = 0;
  b.mesh.kind = MeshSpec::Kind::box;
  b.mesh.box.min = Vec3::Zero();
  b.mesh.box.max = Vec3::Ones();
  for (int k = 0; k < 3; ++k) b.mesh.box.cells[k] = cells;
  scene.bodies.push_back(b);
  return scene;
}

// Shuffles the tets and gives the nodes a random numbering.  (build_model then numbers nodes by
// first use in the shuffled tet order, which is itself random.)
BodyMesh shuffled(const BodyMesh& mesh, std::mt19937_64& rng) {
  const LocalIndex n_nodes = static_cast<LocalIndex>(mesh.coords.size() / 3);
  const LocalIndex n_tets = static_cast<LocalIndex>(mesh.tets.size() / 4);
  std::vector<LocalIndex> node_perm(n_nodes), tet_perm(n_tets);
  std::iota(node_perm.begin(), node_perm.end(), 0);
  std::iota(tet_perm.begin(), tet_perm.end(), 0);
  std::shuffle(node_perm.begin(), node_perm.end(), rng);
  std::shuffle(tet_perm.begin(), tet_perm.end(), rng);
  BodyMesh out;
  out.source = mesh.source + " (shuffled)";
  out.coords.resize(mesh.coords.size());
  for (LocalIndex i = 0; i < n_nodes; ++i)
    for (int k = 0; k < 3; ++k) out.coords[3 * node_perm[i] + k] = mesh.coords[3 * i + k];
  out.tets.resize(mesh.tets.size());
  for (LocalIndex t = 0; t < n_tets; ++t)
    for (int c = 0; c < 4; ++c) out.tets[4 * t + c] = node_perm[mesh.tets[4 * tet_perm[t] + c]];
  return out;
}

// A deformed, moving state: every node displaced and given a velocity at random (0.1 % of the
// cell size, 1 mm/s), so forces are non-zero and no tet inverts.
void perturb(Model& model, double cell_size, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  NodeArrays& nodes = model.nodes;
  for (std::size_t i = 0; i < nodes.x.size(); ++i) {
    nodes.x[i] = nodes.x0(i / 3)[i % 3] + 1e-3 * cell_size * u(rng);
    nodes.v[i] = 1e-3 * u(rng);
  }
}

// Bytes a stage must move per step if each array element crosses the memory bus once (perfect
// reuse of node data within a step), counted like STREAM: reads + writes, no write-allocate.
struct ByteCount {
  double per_tet = 0.0;
  double per_node = 0.0;
  double per_tet_step(double nodes_per_tet) const { return per_tet + per_node * nodes_per_tet; }
};
// forces: tet order 4 + tet nodes 4×4 + dm_inv 72 + volume0 8 + material 4 + viscosity 8;
//         nodes x 24 + f zeroed 24, read 24 and written 24 (v is read only for damped tets;
//         these are undamped).
constexpr ByteCount force_bytes{4 + 16 + 72 + 8 + 4 + 8, 24 + 24 + 24 + 24};
// integrate (unconstrained nodes): mass 8 + mask 1 + f 24 + v 24+24 + x 24+24.
constexpr ByteCount integrate_bytes{0, 8 + 1 + 24 + 48 + 48};

struct Result {
  long tets = 0;
  std::string order, material, stage;
  double seconds_per_step = 0.0, median_seconds_per_step = 0.0;
  double tet_steps_per_second = 0.0, bytes_per_tet_step = 0.0, achieved_GBps = 0.0;
  double fraction_of_stream = 0.0, ratio_to_baseline = 0.0;
};

std::vector<long> parse_sizes(const std::string& text) {
  std::vector<long> sizes;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) sizes.push_back(static_cast<long>(std::stod(item)));
  return sizes;
}

// Comma-separated names of Order; unknown names are an error.
std::vector<Order> parse_orders(const std::string& text) {
  std::vector<Order> orders;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    bool known = false;
    for (const Order o : {Order::sfc, Order::as_generated, Order::random})
      if (item == order_name(o)) {
        orders.push_back(o);
        known = true;
      }
    if (!known) {
      std::fprintf(stderr, "unknown order '%s' (sfc, as_generated, random)\n", item.c_str());
      std::exit(2);
    }
  }
  return orders;
}

[[noreturn]] void usage(const char* program) {
  std::fprintf(
      stderr,
      "usage: %s [out.csv] [--csv PATH] [--sizes 1e4,1e5,1e6] [--no-1e6] "
      "[--orders sfc,as_generated,random] [--min-time SECONDS] [--stream-mb MB] [--wall]\n",
      program);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path = "bench_internal_forces.csv";
  std::vector<long> sizes = {10000, 100000, 1000000};
  double min_seconds = 0.5;
  double stream_mb = 80.0;
  std::vector<Order> orders = {Order::sfc, Order::as_generated, Order::random};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(argv[0]);
      return argv[++i];
    };
    if (arg == "--csv")
      csv_path = value();
    else if (arg == "--sizes")
      sizes = parse_sizes(value());
    else if (arg == "--no-1e6")
      sizes.erase(std::remove_if(sizes.begin(), sizes.end(), [](long n) { return n >= 500000; }),
                  sizes.end());
    else if (arg == "--min-time")
      min_seconds = std::stod(value());
    else if (arg == "--stream-mb")
      stream_mb = std::stod(value());
    else if (arg == "--orders")
      orders = parse_orders(value());
    else if (arg == "--wall")
      use_wall_clock = true;
    else if (arg == "-h" || arg == "--help")
      usage(argv[0]);
    else if (!arg.empty() && arg[0] != '-')
      csv_path = arg;
    else
      usage(argv[0]);
  }
  if (sizes.empty() || orders.empty()) usage(argv[0]);

  const double stream_GBps = triad_bandwidth(stream_mb, 10);
  std::printf("STREAM triad (3 x %.0f MB, best of 10): %.2f GB/s; timer: %s\n", stream_mb,
              stream_GBps, use_wall_clock ? "wall clock" : "thread CPU time");
  std::printf(
      "bytes per tet-step counted once per array element (STREAM convention); node terms scale "
      "with nodes/tet\n\n");

  std::vector<Result> results;
  double sink = 0.0;
  const ElasticModel laws[2] = {ElasticModel::neo_hookean, ElasticModel::st_venant_kirchhoff};

  std::printf("%9s %-13s %-20s %-9s %11s %11s %8s %8s %7s %7s\n", "tets", "order", "material",
              "stage", "ns/tet", "Mtet-st/s", "B/tet", "GB/s", "stream", "vs sfc");
  for (const long target : sizes) {
    const int cells = std::max(1, static_cast<int>(std::lround(std::cbrt(target / 6.0))));
    const double cell_size = 1.0 / cells;
    std::map<std::string, double> baseline;  // stage -> s/step of sfc neo-Hookean
    for (const Order order : orders) {
      for (const ElasticModel law : laws) {
        const Scene scene = box_scene(cells, law);
        std::vector<BodyMesh> meshes = {box_mesh(scene.bodies[0].mesh.box)};
        std::mt19937_64 rng(12345);
        if (order == Order::random) meshes[0] = shuffled(meshes[0], rng);
        Model model = build_model(
            scene, meshes,
            order == Order::sfc ? ElementOrder::space_filling_curve : ElementOrder::as_given);
        meshes.clear();
        perturb(model, cell_size, 777);
        const long n_tets = model.tets.size();
        const double nodes_per_tet = static_cast<double>(model.nodes.size()) / n_tets;
        const InternalForceSummary check = compute_internal_forces(model);
        if (!(check.min_jacobian > 0.0)) {
          std::fprintf(stderr, "perturbed state inverted a tet (J = %g)\n", check.min_jacobian);
          return 1;
        }

        struct Stage {
          const char* name;
          ByteCount bytes;
          bool per_material;
        };
        const Stage stages[2] = {{"forces", force_bytes, true},
                                 {"integrate", integrate_bytes, false}};
        for (const Stage& stage : stages) {
          if (!stage.per_material && law != ElasticModel::neo_hookean) continue;
          const std::string name = stage.name;
          Timing timing;
          if (name == "forces") {
            timing = time_per_call([&] { sink += compute_internal_forces(model).strain_energy; },
                                   min_seconds);
          } else {
            // A tiny step keeps the state (and the later stages' inputs) practically unchanged.
            timing = time_per_call(
                [&] { sink += integrate_central_difference(1e-12, model.nodes).kinetic_energy; },
                min_seconds);
          }
          Result r;
          r.tets = n_tets;
          r.order = order_name(order);
          r.material = stage.per_material ? material_name(law) : "any";
          r.stage = name;
          r.seconds_per_step = timing.best;
          r.median_seconds_per_step = timing.median;
          r.tet_steps_per_second = n_tets / timing.best;
          r.bytes_per_tet_step = stage.bytes.per_tet_step(nodes_per_tet);
          r.achieved_GBps = r.bytes_per_tet_step * r.tet_steps_per_second / 1e9;
          r.fraction_of_stream = r.achieved_GBps / stream_GBps;
          if (order == Order::sfc && (law == ElasticModel::neo_hookean))
            baseline[name] = r.seconds_per_step;
          r.ratio_to_baseline = baseline.count(name) ? baseline[name] / r.seconds_per_step
                                                     : std::nan("");  // no sfc baseline run
          std::printf("%9ld %-13s %-20s %-9s %11.1f %11.2f %8.0f %8.2f %6.1f%% %7.2f\n", r.tets,
                      r.order.c_str(), r.material.c_str(), r.stage.c_str(),
                      1e9 * r.seconds_per_step / n_tets, r.tet_steps_per_second / 1e6,
                      r.bytes_per_tet_step, r.achieved_GBps, 100.0 * r.fraction_of_stream,
                      r.ratio_to_baseline);
          std::fflush(stdout);
          results.push_back(r);
        }
      }
    }
  }

  std::ofstream csv(csv_path);
  if (!csv) {
    std::fprintf(stderr, "cannot write %s\n", csv_path.c_str());
    return 1;
  }
  csv << "tets,order,material,stage,seconds_per_step,tet_steps_per_second,achieved_GBps,"
         "fraction_of_stream,median_seconds_per_step,bytes_per_tet_step,stream_GBps,"
         "ratio_to_sfc_neo_hookean\n";
  csv.precision(6);
  for (const Result& r : results)
    csv << r.tets << ',' << r.order << ',' << r.material << ',' << r.stage << ','
        << r.seconds_per_step << ',' << r.tet_steps_per_second << ',' << r.achieved_GBps << ','
        << r.fraction_of_stream << ',' << r.median_seconds_per_step << ',' << r.bytes_per_tet_step
        << ',' << stream_GBps << ',' << r.ratio_to_baseline << '\n';
  std::printf("\nwrote %s (%zu rows)%s\n", csv_path.c_str(), results.size(),
              sink == 12345.678 ? " " : "");
  return 0;
}
