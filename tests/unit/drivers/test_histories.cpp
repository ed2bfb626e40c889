// histories.csv (drivers/histories, core/history_sums): the reaction of a statically stretched
// bar against E·A·ε, monitor interpolation of linear fields and the stress of a uniform stretch,
// which tet holds a monitor, and through the fdem command: a monitor outside the model, and the
// rows of a restarted run against the uninterrupted run's, and a monitor that ends the run.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "core/history_sums.hpp"
#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "drivers/simulation.hpp"
#include "io/scene_reader.hpp"

using namespace fdem;
using Catch::Matchers::Contains;
using fdem_test::Outcome;
using fdem_test::read_text;
using fdem_test::run_fdem;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

// histories.csv as columns by header name.
std::map<std::string, std::vector<double>> read_histories(const std::string& path) {
  std::stringstream text(read_text(path));
  std::string line;
  std::getline(text, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(text, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t i = 0; std::getline(row, cell, ','); ++i)
      columns[names.at(i)].push_back(std::stod(cell));
  }
  return columns;
}

// A bar [0, L] × [0, a]² of 8 × 2 × 2 cells, ν = 0, held at both ends by region loads.
constexpr double young = 1.0e9, length = 1.0, side = 0.1;  // Pa, m, m
Scene bar_scene() {
  Scene scene = builders::basic_scene(5e-6);
  scene.time.auto_step = false;
  scene.time.step = 1e-6;  // s, well below the critical step (~2e-5 s)
  scene.materials.push_back(builders::elastic_material(1000, young, 0.0));
  scene.bodies.push_back(
      builders::box_body("bar", Vec3::Zero(), Vec3(length, side, side), 8, 2, 2));
  LoadSpec left = builders::load_on_region(Vec3(-1, -1, -1), Vec3(1e-9, 1, 1), Vec3::Zero());
  left.name = "left";
  LoadSpec right =
      builders::load_on_region(Vec3(length - 1e-9, -1, -1), Vec3(2, 1, 1), Vec3::Zero());
  right.name = "right";
  scene.loads = {left, right};
  scene.output.every = 0;
  scene.output.histories.enabled = true;
  scene.output.histories.every = 0;  // every step
  scene.output.histories.loads = {0, 1};
  scene.output.histories.bodies = {0};
  scene.output.histories.monitors = {{"middle", Vec3(0.4, 0.03, 0.05), "test"}};
  return scene;
}

}  // namespace

TEST_CASE("histories: the reaction of a statically stretched bar is E·A·ε",
          "[drivers][histories]") {
  // With ν = 0 a uniform stretch ε along x is the exact static state of the bar held at its
  // ends: no lateral stress, no force on interior or free nodes.  The support's reaction at the
  // right end is then P_xx·A (neo-Hookean: P_xx = μ((1 + ε) − 1/(1 + ε)) = E·ε·(1 − ε/2 + …)),
  // at the left end −P_xx·A; the bar's resultant (supports excluded) is zero.
  TempDir dir;
  RunOptions options;
  options.quiet = true;
  options.output_dir = dir / "out";
  auto sim = make_simulation(bar_scene(), options);
  const double strain = 1e-4;
  NodeArrays& nodes = sim->model().nodes;
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    nodes.x[3 * n] = (1 + strain) * nodes.x0(n)[0];
    for (int k = 0; k < 3; ++k) nodes.v[3 * n + k] = 0.0;
  }
  REQUIRE(sim->run().status == "completed");
  const auto h = read_histories(dir / "out/histories.csv");
  const double area = side * side, mu = young / 2;
  const double exact = mu * ((1 + strain) - 1 / (1 + strain)) * area;  // N
  const double analytic = young * area * strain;                       // N, E·A·ε
  REQUIRE(h.at("time").size() == 5);  // t = 0 … 4 µs, a row every step
  for (std::size_t i = 0; i < h.at("time").size(); ++i) {
    INFO("row " << i << ": right fx " << h.at("load.right.fx")[i] << " N, E A eps " << analytic);
    CHECK(h.at("time")[i] == Approx(1e-6 * i).margin(1e-15));
    CHECK(h.at("load.right.fx")[i] == Approx(exact).epsilon(1e-9));
    CHECK(std::abs(h.at("load.right.fx")[i] / analytic - 1) < 1e-4);  // ε/2 = 5e-5
    CHECK(h.at("load.left.fx")[i] == Approx(-exact).epsilon(1e-9));
    for (const char* c : {"load.right.fy", "load.right.fz", "body.bar.fx", "body.bar.fy"})
      CHECK(std::abs(h.at(c)[i]) < 1e-9 * analytic);
    // Mean displacements: the right end moved ε·L, the left not, the bar's centre ε·L/2.
    CHECK(h.at("load.right.ux")[i] == Approx(strain * length).epsilon(1e-12));
    CHECK(std::abs(h.at("load.left.ux")[i]) < 1e-18);
    CHECK(h.at("body.bar.ux")[i] == Approx(strain * length / 2).epsilon(1e-9));
    // The monitor: u = ε·X, σ_xx = P_xx (J = F_xx), no lateral stress.
    CHECK(h.at("monitor.middle.ux")[i] == Approx(strain * 0.4).epsilon(1e-9));
    CHECK(h.at("monitor.middle.sxx")[i] == Approx(exact / area).epsilon(1e-9));
    CHECK(std::abs(h.at("monitor.middle.syy")[i]) < 1e-6 * exact / area);
  }
}

TEST_CASE(
    "histories: monitors interpolate linear fields exactly, and the stress of a uniform stretch",
    "[drivers][histories]") {
  Scene scene = builders::basic_scene(1.0);
  scene.materials.push_back(builders::elastic_material(2000, 3.0e9, 0.3));
  scene.bodies.push_back(builders::box_body("block", Vec3(-1, 0, 2), Vec3(1, 0.5, 3), 4, 3, 2));
  Model model = build_model(scene, load_body_meshes(scene));
  NodeArrays& nodes = model.nodes;
  // u = A·X + b, v = C·X + d: linear, so the tets' linear interpolation is exact.
  Mat3 A, C;
  A << 0.01, -0.02, 0.005, 0.003, -0.01, 0.02, -0.004, 0.006, 0.015;
  C << 1.0, 2.0, -3.0, 0.5, -0.25, 4.0, -2.0, 1.5, 0.75;
  const Vec3 b(0.1, -0.2, 0.3), d(-5, 6, 7);
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    const Vec3 X = nodes.x0(n);
    vec3_at(nodes.x.data(), n) = X + A * X + b;
    vec3_at(nodes.v.data(), n) = C * X + d;
  }
  const Vec3 points[] = {{0.1234, 0.321, 2.5}, {-0.99, 0.01, 2.01}, {0.5, 0.25, 2.75},
                         {0.777, 0.444, 2.9},  {-0.3, 0.1666, 2.2}, {1.0, 0.5, 3.0}};
  for (const Vec3& X : points) {
    const GlobalId gid = owned_tet_holding(model, X);
    REQUIRE(gid >= 0);
    const MonitorValues m = monitor_values(model, model.tets.find(gid), X);
    INFO("point " << X.transpose());
    CHECK((m.displacement - (A * X + b)).norm() < 1e-14);
    CHECK((m.velocity - (C * X + d)).norm() < 1e-13);
  }
  // A uniform stretch F = diag(λ1, λ2, λ3): neo-Hookean σ = μ/J (F·Fᵀ − I) + λ_L ln J / J · I.
  const Vec3 stretch(1.02, 0.99, 1.005);
  for (LocalIndex n = 0; n < nodes.size(); ++n)
    vec3_at(nodes.x.data(), n) = stretch.cwiseProduct(nodes.x0(n));
  const double E = 3.0e9, nu = 0.3, mu = E / (2 * (1 + nu)),
               lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double J = stretch.prod();
  for (const Vec3& X : points) {
    const MonitorValues m = monitor_values(model, model.tets.find(owned_tet_holding(model, X)), X);
    for (int i = 0; i < 3; ++i) {
      const double expected = mu / J * (stretch[i] * stretch[i] - 1) + lambda * std::log(J) / J;
      CHECK(m.stress(i, i) == Approx(expected).epsilon(1e-12));
      CHECK(std::abs(m.stress(i, (i + 1) % 3)) < 1e-12 * std::abs(expected));
    }
  }
}

TEST_CASE("histories: a monitor sits in the lowest-gid tet holding it, or in none",
          "[drivers][histories]") {
  Scene scene = builders::basic_scene(1.0);
  scene.materials.push_back(builders::elastic_material(2000, 3.0e9, 0.3));
  scene.bodies.push_back(builders::box_body("block", Vec3::Zero(), Vec3(1, 1, 1), 2, 2, 2));
  const Model model = build_model(scene, load_body_meshes(scene));
  // The centre is a node of 24 tets, a mid-edge point of several, a face point of two.
  for (const Vec3& X : {Vec3(0.5, 0.5, 0.5), Vec3(0.25, 0.5, 0.5), Vec3(0.5, 0.5, 0.0)}) {
    GlobalId lowest = -1;
    int holders = 0;
    for (LocalIndex t = 0; t < model.tets.size(); ++t) {
      const auto l = reference_barycentric(model, t, X);
      if (l[0] >= -1e-9 && l[1] >= -1e-9 && l[2] >= -1e-9 && l[3] >= -1e-9) {
        ++holders;
        if (lowest < 0 || model.tets.gid[t] < lowest) lowest = model.tets.gid[t];
      }
    }
    INFO("point " << X.transpose() << ": " << holders << " tets hold it");
    CHECK(holders >= 2);
    CHECK(owned_tet_holding(model, X) == lowest);
  }
  CHECK(owned_tet_holding(model, Vec3(1.001, 0.5, 0.5)) == -1);
  CHECK(owned_tet_holding(model, Vec3(0.5, 0.5, -1e-6)) == -1);
}

namespace {

// A block pushed along a fixed base by a region load (friction), with a monitor, histories every
// 0.5 ms, checkpoints every 2 ms.
const char* pushed_block = R"(name: pushed-block
time: {end: 0.006}
gravity: [0, 0, -9.81]
materials:
  stone:
    density: 2500
    elastic: {young: 1.0e8, poisson: 0.2}
    contact: {friction: 0.6}
bodies:
  - {name: base, mesh: {box: {min: [0, 0, -0.1], max: [1, 0.2, 0], cells: [4, 1, 1]}},
     material: stone, fixed: true}
  - {name: block, mesh: {box: {min: [0.1, 0, 0.0005], max: [0.3, 0.2, 0.2], cells: [2, 1, 2]}},
     material: stone}
loads:
  - {name: pusher, region: {box: {min: [0.09, -1, 0.05], max: [0.11, 1, 1]}},
     velocity: [0.5, null, null]}
output:
  every: 0
  checkpoint_every: 0.002
  histories:
    every: 0.0005
    bodies: [base, block]
    monitors: [{name: inside, point: [0.2, 0.1, 0.1]}]
)";

}  // namespace

TEST_CASE("histories: a monitor outside the model stops the run, naming line and point",
          "[drivers][histories][cli]") {
  TempDir dir;
  std::string scene = pushed_block;
  scene.replace(scene.find("[0.2, 0.1, 0.1]"), 15, "[0.2, 0.1, 0.5]");
  write_text(dir / "scene.yaml", scene);
  const Outcome o = run_fdem(dir, "run scene.yaml -o out -q");
  INFO(o.err);
  CHECK(o.exit_code == 2);
  CHECK_THAT(o.err, Contains("scene.yaml:23:38: output.histories.monitors[0].point: monitor "
                             "'inside' at (0.2, 0.1, 0.5) m lies in no tetrahedron"));
}

TEST_CASE("histories: a restarted run's rows are the uninterrupted run's at the same times",
          "[drivers][histories][cli][restart]") {
  TempDir dir;
  write_text(dir / "scene.yaml", pushed_block);
  const Outcome first = run_fdem(dir, "run scene.yaml -o first -q");
  INFO(first.err);
  REQUIRE(first.exit_code == 0);
  std::string checkpoint;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "first"))
    if (entry.path().extension() == ".h5" &&
        (checkpoint.empty() || entry.path().string() < checkpoint))
      checkpoint = entry.path().string();
  REQUIRE_FALSE(checkpoint.empty());
  const Outcome again = run_fdem(dir, "run scene.yaml -o again -q --restart " + checkpoint);
  INFO(again.err);
  REQUIRE(again.exit_code == 0);
  const std::string uninterrupted = read_text(dir / "first/histories.csv");
  std::stringstream restarted(read_text(dir / "again/histories.csv"));
  std::string line, header;
  std::getline(restarted, header);
  CHECK(uninterrupted.rfind(header + "\n", 0) == 0);  // the same columns
  int rows = 0;
  while (std::getline(restarted, line)) {
    INFO("restarted row " << line);
    CHECK(uninterrupted.find("\n" + line + "\n") != std::string::npos);
    ++rows;
  }
  // 12 rows in 6 ms; the earliest checkpoint kept is the one of 4 ms (the newest two are kept),
  // and the restart from it writes the rows of 4, 4.5, 5 and 5.5 ms.
  CHECK(read_histories(dir / "first/histories.csv").at("time").size() == 12);
  CHECK(rows == 4);
  // The pusher's reaction: it drives the block, so along x it pushes (> 0) once in contact.
  const auto h = read_histories(dir / "first/histories.csv");
  CHECK(h.at("load.pusher.fx").back() > 0);
  CHECK(h.at("load.pusher.ux").back() == Approx(0.5 * h.at("time").back()).epsilon(0.01));
}

namespace {

// A cube falling freely (no contact) with a monitor that ends the run once it has fallen 1 cm;
// rows every 1 ms.  Its centre falls ½ g t² (central differences from rest under a constant force
// give exactly ½ g t² at the steps), so 1 cm is first reached at the row taken at the first step
// past 46 ms (45 ms: 9.93 mm, 46 ms: 10.38 mm).
const char* falling_cube = R"(name: falling-cube
time: {end: 1.0}
gravity: [0, 0, -9.81]
materials:
  stone: {density: 2500, elastic: {young: 1.0e8, poisson: 0.2}}
bodies:
  - {name: cube, mesh: {box: {min: [0, 0, 0], max: [0.1, 0.1, 0.1], cells: [1, 1, 1]}},
     material: stone}
output:
  every: 0
  histories:
    every: 0.001
    monitors: [{name: centre, point: [0.05, 0.05, 0.05], stop_displacement: 0.01}]
)";

}  // namespace

TEST_CASE("histories: a monitor's stop_displacement ends the run at the first row beyond it",
          "[drivers][histories][cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", falling_cube);
  const Outcome o = run_fdem(dir, "run scene.yaml -o out");
  INFO(o.err);
  REQUIRE(o.exit_code == 0);
  CHECK_THAT(o.err, Contains("fdem: stopped at t = 0.046"));
  CHECK_THAT(o.err, Contains("s: monitor 'centre' has moved 0.010"));
  const std::string summary = read_text(dir / "out/summary.json");
  CHECK_THAT(summary, Contains("\"status\": \"completed\""));
  CHECK_THAT(summary, Contains("at least its stop_displacement 0.01 m"));
  const auto h = read_histories(dir / "out/histories.csv");
  REQUIRE(h.at("time").size() == 47);    // rows from 0 to 46 ms: the last one is the stop's
  const double t = h.at("time").back();  // the first step at or after 46 ms
  CHECK(t >= 0.046);
  CHECK(t < 0.046 + 0.001);
  CHECK(-h.at("monitor.centre.uz").back() == Approx(0.5 * 9.81 * t * t).epsilon(1e-6));
  CHECK(-h.at("monitor.centre.uz")[45] < 0.01);
  CHECK(-h.at("monitor.centre.uz").back() >= 0.01);

  // Without output files (the simulation alone, as tests and scripts run it) it ends alike.
  Scene scene = parse_scene(falling_cube, dir / "scene.yaml");
  RunOptions options;
  options.write_output = false;
  auto sim = make_simulation(scene, options);
  const RunReport report = sim->run();
  CHECK(report.status == "completed");
  CHECK_THAT(report.reason, Contains("monitor 'centre' has moved"));
  CHECK(report.steps > 0);
  CHECK(std::abs(report.time - t) <= sim->time_step() * (1 + 1e-9));  // the step after the row

  // fdem check says so.
  const Outcome check = run_fdem(dir, "check scene.yaml");
  CHECK_THAT(check.out, Contains("monitor centre (ends the run when it has moved 0.01 m)"));
}

TEST_CASE("histories: fdem check warns of a stop_displacement on a monitor no load can move",
          "[drivers][histories][cli]") {
  TempDir dir;
  // The falling cube on a fixed slab, the monitor in the slab: it can never move.
  std::string scene = falling_cube;
  const std::string cube_body = "  - {name: cube,";
  scene.replace(scene.find(cube_body), 0,
                "  - {name: slab, fixed: true, mesh: {box: {min: [-0.2, -0.2, -0.2], max: [0.3, "
                "0.3, -0.1], cells: [1, 1, 1]}},\n     material: stone}\n");
  const std::string centre = "point: [0.05, 0.05, 0.05]";
  scene.replace(scene.find(centre), centre.size(), "point: [0.05, 0.05, -0.15]");
  write_text(dir / "at_rest.yaml", scene);
  const Outcome at_rest = run_fdem(dir, "check at_rest.yaml");
  INFO(at_rest.out << at_rest.err);
  REQUIRE(at_rest.exit_code == 0);
  CHECK_THAT(at_rest.out, Contains("warning: monitor 'centre' lies in fixed body 'slab', which no "
                                   "velocity or base-motion load moves: its stop_displacement "
                                   "can never end the run"));

  // A base motion of the slab moves it: no warning.
  write_text(dir / "ground.csv", "time,acceleration\n0,0\n1,1\n");
  write_text(dir / "moved.yaml", scene +
                                     "loads:\n  - {bodies: [slab], base_motion: {file: ground.csv, "
                                     "direction: [1, 0, 0]}}\n");
  const Outcome moved = run_fdem(dir, "check moved.yaml");
  INFO(moved.out << moved.err);
  REQUIRE(moved.exit_code == 0);
  CHECK_THAT(moved.out, !Contains("can never end the run"));

  // The monitor in the falling cube: no warning.
  write_text(dir / "falling.yaml", falling_cube);
  const Outcome falling = run_fdem(dir, "check falling.yaml");
  REQUIRE(falling.exit_code == 0);
  CHECK_THAT(falling.out, !Contains("can never end the run"));
}
