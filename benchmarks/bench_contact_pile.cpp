// Dense falling pile: k×k×k blocks (2×2×2 cells, 48 tets each) stacked with small gaps on a fixed
// base, under gravity with a downward velocity so that every block is in contact within a few
// steps.  Reports the share of step time spent in contact detection and contact forces, the
// candidate and overlapping pairs per tet, contact pair evaluations per second and tet-steps per
// second per core.  Writes CSV (argv[1], default bench_contact_pile.csv).
//
//   bench_contact_pile [out.csv] [--sizes 2,4,6] [--steps 1500]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "drivers/simulation.hpp"

using namespace fdem;

namespace {

Scene pile_scene(int k) {
  const double a = 0.2, gap = 0.0;  // block edge and gap (m): stacked touching
  Scene scene;
  scene.name = "pile";
  scene.source_path = "bench_contact_pile";
  scene.time.end = 1.0;
  scene.time.safety = 0.7;
  scene.gravity = Vec3(0, 0, -9.81);
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
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) sizes.push_back(std::stoi(s));
    } else if (a == "--steps" && i + 1 < argc) {
      steps = std::stol(argv[++i]);
    } else {
      csv_path = a;
    }
  }
  std::ofstream csv(csv_path);
  csv << "blocks,tets,steps,seconds,tet_steps_per_second,contact_share,detection_share,candidates_"
         "per_tet,"
         "active_per_tet,pair_evaluations_per_second,detections\n";
  std::printf("%7s %7s %6s %9s %12s %9s %9s %10s %10s %14s %6s\n", "blocks", "tets", "steps",
              "seconds", "tet-st/s", "contact%", "detect%", "cand/tet", "active/tet",
              "pair-evals/s", "det");
  for (int k : sizes) {
    const Scene scene = pile_scene(k);
    RunOptions options;
    options.quiet = true;
    options.write_output = false;
    auto sim = make_simulation(scene, options);
    // Let the blocks land (every block in contact), then measure.
    for (int i = 0; i < 300; ++i) sim->step();
    const RunReport before = sim->report();
    long candidates = 0, active = 0;
    const long detections_before = sim->contact_stage()->detections();
    const auto start = std::chrono::steady_clock::now();
    for (long s = 0; s < steps; ++s) {
      sim->step();
      candidates += static_cast<long>(sim->contact_stage()->candidates().size());
      active += static_cast<long>(sim->contact_stage()->records().size());
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
    std::printf("%7d %7.0f %6ld %9.3f %12.4g %8.1f%% %8.1f%% %10.2f %10.3f %14.4g %6ld\n",
                k * k * k, tets, steps, seconds, tets * steps / seconds, 100 * contact / total,
                100 * detection / total, double(candidates) / steps / tets,
                double(active) / steps / tets, candidates / contact, detections);
    csv << k * k * k << ',' << tets << ',' << steps << ',' << seconds << ','
        << tets * steps / seconds << ',' << contact / total << ',' << detection / total << ','
        << double(candidates) / steps / tets << ',' << double(active) / steps / tets << ','
        << candidates / contact << ',' << detections << '\n';
  }
  return 0;
}
