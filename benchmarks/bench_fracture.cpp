// Cost of fracture in the step loop: tet-steps per second (thread CPU time, one core) of a box
// body of n³ cells (6 tets each) for
//   plain       the body without joints (one piece: no contact stage)
//   intact      the body with `joints: all`, joints intact (joint stage + contact among the tets
//               that share no joint)
//   fragmenting the jointed body stretched by v = v0·(2x/L − 1) along x until it breaks apart
// with the stage shares of the step.
//
// Usage: bench_fracture [out.csv] [--cells N[,N...]] [--steps S]
//   defaults: bench_fracture.csv, cells 6,10, 200 steps per case.
#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/model.hpp"
#include "drivers/scene_builders.hpp"
#include "drivers/simulation.hpp"

using namespace fdem;

namespace {

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Case {
  std::string name;
  int cells;
  long tets = 0, joints = 0, broken = 0, pairs = 0;
  double rate = 0;  // tet-steps per CPU second
  double share_internal = 0, share_joints = 0, share_contact = 0;
};

Case run(const std::string& name, int cells, long steps) {
  const double size = 0.1;
  Scene scene;
  scene.name = "bench_fracture";
  scene.source_path = "bench_fracture";
  scene.time.end = 1.0;
  MaterialSpec m;
  m.name = "rock";
  m.density = 2500;
  m.elastic.young = 30e9;
  m.elastic.poisson = 0.2;
  m.fracture = builders::rock_fracture();
  m.contact.friction = 0.5;
  scene.materials.push_back(m);
  BodySpec body;
  body.name = "box";
  body.material = 0;
  body.mesh.box.max = Vec3::Constant(size);
  for (int& c : body.mesh.box.cells) c = cells;
  if (name != "plain") body.joints = JointPlacement::all;
  scene.bodies.push_back(body);
  RunOptions options;
  options.quiet = true;
  options.write_output = false;
  auto sim = make_simulation(scene, options);
  Model& model = sim->model();
  // Stretching velocity field v = v0·(2x/L − 1): v0 = 20 m/s gives ~4 MPa of dynamic tension
  // (the jointed body breaks apart within a few wave transits), 0.5 m/s stays elastic.
  const double v0 = name == "fragmenting" ? 20.0 : 0.5;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    model.nodes.v[3 * n] = v0 * (2 * model.nodes.x0(n)[0] / size - 1);
  sim->step();  // first detection outside the timing
  const double t0 = cpu_seconds();
  for (long s = 0; s < steps; ++s) sim->step();
  const double seconds = cpu_seconds() - t0;
  Case c;
  c.name = name;
  c.cells = cells;
  c.tets = model.tets.size();
  c.joints = model.joints.size();
  for (auto b : model.joints.broken) c.broken += b;
  if (sim->contact_stage()) c.pairs = sim->contact_stage()->candidates().size();
  c.rate = double(c.tets) * steps / seconds;
  double total = 0;
  const auto report = sim->report();
  for (const auto& st : report.stages) total += st.seconds;
  for (const auto& st : report.stages) {
    if (st.name == "internal_forces") c.share_internal = st.seconds / total;
    if (st.name == "joint_forces" || st.name == "fracture") c.share_joints += st.seconds / total;
    if (st.name == "contact_detection" || st.name == "contact_forces")
      c.share_contact += st.seconds / total;
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "bench_fracture.csv";
  std::vector<int> cells = {6, 10};
  long steps = 200;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--cells" && i + 1 < argc) {
      cells.clear();
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');) cells.push_back(std::stoi(item));
    } else if (a == "--steps" && i + 1 < argc) {
      steps = std::atol(argv[++i]);
    } else {
      out = a;
    }
  }
  std::ofstream csv(out);
  csv << "case,cells,tets,joints,broken,candidate_pairs,tet_steps_per_second,share_internal,"
         "share_joints,share_contact\n";
  std::printf("%-12s %6s %7s %7s %7s %9s %14s %9s %7s %8s\n", "case", "cells", "tets", "joints",
              "broken", "pairs", "tet-steps/s", "internal", "joints", "contact");
  for (int n : cells)
    for (const char* name : {"plain", "intact", "fragmenting"}) {
      const Case c = run(name, n, steps);
      std::printf("%-12s %6d %7ld %7ld %7ld %9ld %14.3e %8.1f%% %6.1f%% %7.1f%%\n", c.name.c_str(),
                  n, c.tets, c.joints, c.broken, c.pairs, c.rate, 100 * c.share_internal,
                  100 * c.share_joints, 100 * c.share_contact);
      csv << c.name << ',' << n << ',' << c.tets << ',' << c.joints << ',' << c.broken << ','
          << c.pairs << ',' << c.rate << ',' << c.share_internal << ',' << c.share_joints << ','
          << c.share_contact << '\n';
    }
  return 0;
}
