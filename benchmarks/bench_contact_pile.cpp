// Dense falling pile: k×k×k blocks (2×2×2 cells, 48 tets each) stacked with small gaps on a fixed
// base, under gravity with a downward velocity so that every block is in contact within a few
// steps.  Reports the share of step time spent in contact detection and contact forces, the
// candidate and overlapping pairs per tet, contact pair evaluations per second and tet-steps per
// second per core (CPU time of the process).  Each size runs with each contact narrowing in turn
// (`exact`, the default, and `face_planes`, the previous algorithm): the same pairs overlap, fewer
// are evaluated; and with each contact.sliver_tolerance of --slivers (default: 0, which
// integrates every pair the face planes pass, then 1e-6, the default).  speed-up: against the
// size's first variant.  Writes CSV (argv[1],
// default bench_contact_pile.csv).
//
//   bench_contact_pile [out.csv] [--sizes 2,4,6] [--steps 1500] [--narrowing face_planes,exact]
//                      [--slivers 0,1e-6]
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "drivers/simulation.hpp"

using namespace fdem;

namespace {

Scene pile_scene(int k, bool exact_narrowing, double sliver_tolerance) {
  const double a = 0.2, gap = 0.0;  // block edge and gap (m): stacked touching
  Scene scene;
  scene.name = "pile";
  scene.source_path = "bench_contact_pile";
  scene.time.end = 1.0;
  scene.time.safety = 0.7;
  scene.gravity = Vec3(0, 0, -9.81);
  scene.contact_exact_narrowing = exact_narrowing;
  scene.contact_sliver_tolerance = sliver_tolerance;
  MaterialSpec stone;
  stone.name = "stone";
  stone.density = 2500;
  stone.elastic.young = 1e9;
  stone.elastic.poisson = 0.2;
  stone.contact.friction = 0.5;
  scene.materials.push_back(stone);
  BodySpec base;
  base.name = "base";
  base.material = 0;
  base.fixed = true;
  base.mesh.box.min = Vec3(-0.1, -0.1, -0.2);
  base.mesh.box.max = Vec3(k * (a + gap) + 0.1, k * (a + gap) + 0.1, 0);
  base.mesh.box.cells[0] = base.mesh.box.cells[1] = 2 * k + 1;
  base.mesh.box.cells[2] = 1;
  scene.bodies.push_back(base);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l) {
        BodySpec b;
        b.name = "b" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(l);
        b.material = 0;
        const Vec3 lo(i * (a + gap), j * (a + gap), l * (a + gap));
        b.mesh.box.min = lo;
        b.mesh.box.max = lo + Vec3(a, a, a);
        b.mesh.box.cells[0] = b.mesh.box.cells[1] = b.mesh.box.cells[2] = 2;
        b.velocity = Vec3(0.01 * (i - j), 0.01 * (l - i), -0.5);
        scene.bodies.push_back(b);
      }
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  std::string csv_path = "bench_contact_pile.csv";
  std::vector<int> sizes = {2, 4, 6};
  long steps = 1500;
  std::vector<std::string> narrowings = {"face_planes", "exact"};
  std::vector<double> sliver_tolerances = {0.0, 1e-6};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) sizes.push_back(std::stoi(s));
    } else if (a == "--narrowing" && i + 1 < argc) {
      narrowings.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) {
        if (s != "exact" && s != "face_planes") {
          std::fprintf(stderr, "--narrowing: '%s' is not exact or face_planes\n", s.c_str());
          return 2;
        }
        narrowings.push_back(s);
      }
    } else if (a == "--slivers" && i + 1 < argc) {
      sliver_tolerances.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) sliver_tolerances.push_back(std::stod(s));
    } else if (a == "--steps" && i + 1 < argc) {
      steps = std::stol(argv[++i]);
    } else {
      csv_path = a;
    }
  }
  std::ofstream csv(csv_path);
  csv << "blocks,narrowing,sliver_tolerance,tets,steps,cpu_seconds,tet_steps_per_second,contact_"
         "share,detection_"
         "share,candidates_per_tet,active_per_tet,pair_evaluations_per_second,detections,speedup,"
         "state_hash\n";
  std::printf("%7s %12s %8s %7s %6s %9s %12s %9s %9s %10s %10s %14s %6s %8s %s\n", "blocks",
              "narrowing", "slivers", "tets", "steps", "CPU s", "tet-st/s", "contact%", "detect%",
              "cand/tet", "active/tet", "pair-evals/s", "det", "speed-up", "state_hash");
  for (int k : sizes) {
    double first_seconds = 0.0;
    for (const std::string& narrowing : narrowings)
      for (const double slivers : sliver_tolerances) {
        const Scene scene = pile_scene(k, narrowing == "exact", slivers);
        RunOptions options;
        options.quiet = true;
        options.write_output = false;
        auto sim = make_simulation(scene, options);
        // Let the blocks land (every block in contact), then measure.
        for (int i = 0; i < 300; ++i) sim->step();
        const RunReport before = sim->report();
        long candidates = 0, active = 0;
        const long detections_before = sim->contact_stage()->detections();
        const std::clock_t start = std::clock();
        for (long s = 0; s < steps; ++s) {
          sim->step();
          candidates += static_cast<long>(sim->contact_stage()->candidates().size());
          active += static_cast<long>(sim->contact_stage()->records().size());
        }
        const double seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
        if (first_seconds == 0.0) first_seconds = seconds;
        const RunReport after = sim->report();
        double total = 0, contact = 0, detection = 0;
        for (std::size_t i = 0; i < after.stages.size(); ++i) {
          const double dt = after.stages[i].seconds - before.stages[i].seconds;
          if (after.stages[i].name == "output") continue;
          total += dt;
          if (after.stages[i].name == "contact_forces") contact += dt;
          if (after.stages[i].name == "contact_detection") detection += dt;
        }
        const double tets = sim->model().tets.size();
        const long detections = sim->contact_stage()->detections() - detections_before;
        const std::string hash = sim->report().state_hash;
        std::printf(
            "%7d %12s %8.0e %7.0f %6ld %9.3f %12.4g %8.1f%% %8.1f%% %10.2f %10.3f %14.4g %6ld "
            "%8.2f %s\n",
            k * k * k, narrowing.c_str(), slivers, tets, steps, seconds, tets * steps / seconds,
            100 * contact / total, 100 * detection / total, double(candidates) / steps / tets,
            double(active) / steps / tets, candidates / contact, detections,
            first_seconds / seconds, hash.c_str());
        csv << k * k * k << ',' << narrowing << ',' << slivers << ',' << tets << ',' << steps << ','
            << seconds << ',' << tets * steps / seconds << ',' << contact / total << ','
            << detection / total << ',' << double(candidates) / steps / tets << ','
            << double(active) / steps / tets << ',' << candidates / contact << ',' << detections
            << ',' << first_seconds / seconds << ',' << hash << '\n';
      }
  }
  return 0;
}
