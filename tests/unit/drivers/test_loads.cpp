// Time-dependent loads: ground velocity from an acceleration record (exact integral of the
// piecewise-linear record), CSV messages, tilt angle and gravity over time, the reader's keys, and
// the loads acting through Simulation::step (free fall under tilting gravity, a moving base).
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "drivers/loads.hpp"
#include "drivers/simulation.hpp"
#include "io/scene_reader.hpp"

using namespace fdem;
using Catch::Matchers::Contains;

namespace {

// This process's directory of record files, removed when the process ends (ctest runs every test
// case as a process of its own: left behind, they pile up in the temporary directory).
const std::filesystem::path& temp_dir() {
  struct Directory {
    std::filesystem::path path;
    ~Directory() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Directory directory{std::filesystem::temp_directory_path() /
                                   ("fdem_loads_" + std::to_string(::getpid()))};
  return directory.path;
}

std::string temp_file(const std::string& name, const std::string& text) {
  const std::filesystem::path& dir = temp_dir();
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string record_error(const std::string& text) {
  BaseMotionSpec spec;
  try {
    read_acceleration_record(temp_file("bad.csv", text), spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

Scene block_scene(double end) {
  Scene s;
  s.name = s.source_path = "loads";
  s.time.end = end;
  MaterialSpec m;
  m.name = "stone";
  m.density = 2000;
  m.elastic.young = 1e8;
  m.elastic.poisson = 0.2;
  s.materials.push_back(m);
  BodySpec b;
  b.name = "block";
  b.material = 0;
  b.mesh.box.max = Vec3(0.2, 0.2, 0.2);
  s.bodies.push_back(b);
  return s;
}

std::unique_ptr<Simulation> quiet(const Scene& scene) {
  RunOptions o;
  o.quiet = true;
  o.write_output = false;
  return make_simulation(scene, o);
}

}  // namespace

TEST_CASE("base velocity is the exact integral of the piecewise-linear record",
          "[drivers][loads]") {
  BaseMotionSpec spec;
  spec.time = {0.0, 1.0, 2.0, 3.0};
  spec.acceleration = {0.0, 2.0, 2.0, 0.0};  // ramp up, hold, ramp down
  spec.scale = 0.5;
  CHECK(base_velocity(spec, -1.0) == 0.0);
  CHECK(base_velocity(spec, 0.0) == 0.0);
  CHECK(base_velocity(spec, 0.5) == Approx(0.5 * 0.25));  // ∫ 2t = t² → 0.25
  CHECK(base_velocity(spec, 1.0) == Approx(0.5 * 1.0));
  CHECK(base_velocity(spec, 1.5) == Approx(0.5 * 2.0));
  CHECK(base_velocity(spec, 2.5) == Approx(0.5 * (3.0 + 2.0 * 0.5 - 0.25)));
  CHECK(base_velocity(spec, 3.0) == Approx(0.5 * 4.0));
  CHECK(base_velocity(spec, 10.0) == Approx(0.5 * 4.0));  // zero acceleration after the record
  // A record starting later: at rest until its first sample.
  spec.time = {1.0, 2.0};
  spec.acceleration = {3.0, 3.0};
  spec.scale = 1.0;
  CHECK(base_velocity(spec, 0.9) == 0.0);
  CHECK(base_velocity(spec, 1.5) == Approx(1.5));
  // A sine record sampled every 1 ms: velocity (1 − cos ωt)/ω within the chord error.
  const double w = 2 * M_PI * 2.0;
  spec.time.clear();
  spec.acceleration.clear();
  for (int i = 0; i <= 2000; ++i) {
    spec.time.push_back(i * 1e-3);
    spec.acceleration.push_back(std::sin(w * i * 1e-3));
  }
  for (double t : {0.1, 0.37, 1.2, 1.99})
    CHECK(base_velocity(spec, t) == Approx((1 - std::cos(w * t)) / w).margin(3e-5));  // h²ω²t/12
}

TEST_CASE("acceleration records: header, comments, and a clear message with the line",
          "[drivers][loads]") {
  BaseMotionSpec spec;
  read_acceleration_record(temp_file("ok.csv",
                                     "# synthetic\n"
                                     "time, acceleration\n"
                                     "0, 0\n"
                                     "\n"
                                     "0.5, 1.5e-1\n"
                                     "1.0 , -2\n"),
                           spec);
  REQUIRE(spec.time.size() == 3);
  CHECK(spec.time[2] == 1.0);
  CHECK(spec.acceleration[1] == 0.15);
  CHECK(spec.acceleration[2] == -2.0);

  CHECK_THAT(record_error("time,acc\n0,0\n0.1,abc\n"),
             Contains("bad.csv:3:") && Contains("expected a row 'time, acceleration'") &&
                 Contains("got '0.1,abc'"));
  CHECK_THAT(record_error("0,0\n0.1;2\n"), Contains("bad.csv:2:"));
  CHECK_THAT(record_error("0,0\n0.1,1,2\n"), Contains("bad.csv:2:"));
  CHECK_THAT(record_error("0,0\n0.2,1\n0.1,1\n"),
             Contains("bad.csv:3:") && Contains("does not increase"));
  CHECK_THAT(record_error("-0.1,0\n0.2,1\n"), Contains("bad.csv:1:") && Contains("negative"));
  CHECK_THAT(record_error("time,acc\n0,1\n"), Contains("at least two rows") && Contains("found 1"));
  CHECK_THAT(record_error("header one\nheader two\n0,1\n"), Contains("bad.csv:2:"));
  CHECK_THROWS_WITH(read_acceleration_record("/nonexistent/record.csv", spec),
                    Contains("/nonexistent/record.csv: cannot open"));
}

TEST_CASE("tilt angle grows at its rate from its start up to its maximum, ramps add to gravity",
          "[drivers][loads]") {
  Scene s;
  s.gravity = Vec3(0, 0, -10);
  LoadSpec tilt;
  tilt.kind = LoadSpec::Kind::tilt;
  tilt.tilt.axis = Vec3(0, 1, 0);
  tilt.tilt.rate = 10 * M_PI / 180;
  tilt.tilt.max = 30 * M_PI / 180;
  tilt.tilt.start = 0.5;
  s.loads.push_back(tilt);
  CHECK(tilt_angle(tilt.tilt, 0.2) == 0.0);
  CHECK(tilt_angle(tilt.tilt, 1.5) == Approx(10 * M_PI / 180));
  CHECK(tilt_angle(tilt.tilt, 9.0) == Approx(30 * M_PI / 180));
  // About +y, right hand: −z turns towards −x.
  const double a = 20 * M_PI / 180;
  CHECK((gravity_at(s, 2.5) - Vec3(-10 * std::sin(a), 0, -10 * std::cos(a))).norm() < 1e-12);
  CHECK(gravity_at(s, 2.5).norm() == Approx(10));
  LoadSpec ramp;
  ramp.kind = LoadSpec::Kind::ramp;
  ramp.ramp.direction = Vec3(1, 0, 0);
  ramp.ramp.rate = 2.0;
  ramp.ramp.max = 3.0;
  s.loads.push_back(ramp);
  CHECK(ramp_acceleration(ramp.ramp, 1.0) == Approx(2.0));
  CHECK(ramp_acceleration(ramp.ramp, 5.0) == Approx(3.0));
  CHECK((gravity_at(s, 1.0) -
         Vec3(-10 * std::sin(5 * M_PI / 180) + 2.0, 0, -10 * std::cos(5 * M_PI / 180)))
            .norm() < 1e-12);
}

TEST_CASE("scene reader: base_motion, tilt and ramp loads and their messages", "[drivers][loads]") {
  const std::string record = temp_file("record.csv", "0,0\n1,1\n");
  const std::string head =
      "time: {end: 0.1}\n"
      "gravity: [0, 0, -9.81]\n"
      "materials:\n"
      "  rock: {density: 2500, elastic: {young: 1.0e9, poisson: 0.25}}\n"
      "bodies:\n"
      "  - {name: base, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, material: rock}\n"
      "loads:\n";
  const Scene s = parse_scene(head + "  - {bodies: [base], base_motion: {file: " + record +
                                  ", direction: [2, 0, 0], scale: 9.81}}\n"
                                  "  - {tilt: {axis: [0, 1, 0], rate: 5, max: 30, start: 0.2}}\n"
                                  "  - {ramp: {direction: [0, 1, 0], rate: 0.5, max: 2}}\n",
                              "scene.yaml");
  REQUIRE(s.loads.size() == 3);
  CHECK(s.loads[0].kind == LoadSpec::Kind::base_motion);
  CHECK(s.loads[0].bodies == std::vector<int>{0});
  CHECK(s.loads[0].base_motion.file == record);
  CHECK(s.loads[0].base_motion.direction == Vec3(1, 0, 0));
  CHECK(s.loads[0].base_motion.scale == 9.81);
  CHECK(s.loads[0].dof_mask == 7);
  CHECK(s.loads[1].kind == LoadSpec::Kind::tilt);
  CHECK(s.loads[1].tilt.rate == Approx(5 * M_PI / 180));
  CHECK(s.loads[1].tilt.max == Approx(30 * M_PI / 180));
  CHECK(s.loads[1].tilt.start == 0.2);
  CHECK(s.loads[2].kind == LoadSpec::Kind::ramp);
  CHECK(s.loads[2].ramp.max == 2);

  const auto error = [&](const std::string& load) {
    try {
      parse_scene(head + load, "scene.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(
      error("  - {bodies: [base], base_motion: {file: missing.csv, direction: [1, 0, 0]}}\n"),
      Contains("scene.yaml:8:") && Contains("loads[0].base_motion.file") &&
          Contains("does not exist"));
  CHECK_THAT(
      error("  - {bodies: [base], base_motion: {file: " + record + ", direction: [0, 0, 0]}}\n"),
      Contains("loads[0].base_motion.direction") && Contains("must not be [0, 0, 0]"));
  CHECK_THAT(error("  - {region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, base_motion: {file: " +
                   record + ", direction: [1, 0, 0]}}\n"),
             Contains("loads[0]") && Contains("moves whole bodies"));
  CHECK_THAT(error("  - {tilt: {axis: [0, 1, 0], rate: 5, max: 30}, bodies: [base]}\n"),
             Contains("loads[0]") && Contains("give it alone"));
  CHECK_THAT(error("  - {tilt: {axis: [0, 1, 0], rate: 5}}\n"),
             Contains("loads[0].tilt.max") && Contains("missing required key 'max'"));
  CHECK_THAT(error("  - {ramp: {direction: [1, 0, 0], rate: 5, maxi: 3}}\n"),
             Contains("loads[0].ramp.maxi") && Contains("Did you mean 'max'?"));
  CHECK_THAT(error("  - {bodies: [base]}\n"),
             Contains("loads[0].velocity") && Contains("base_motion, tilt or ramp"));
  CHECK_THAT(error("  - {tilt: {axis: [0, 1, 0], rate: -5, max: 30}}\n"),
             Contains("loads[0].tilt.rate") && Contains("must be > 0"));
  // A tilt about the gravity's own direction, or of no gravity, would turn nothing.
  CHECK_THAT(
      error("  - {tilt: {axis: [0, 0, 2], rate: 5, max: 30}}\n"),
      Contains("scene.yaml:8:") && Contains("loads[0].tilt.axis") && Contains("along the gravity"));
  std::string weightless = head;
  weightless.replace(weightless.find("[0, 0, -9.81]"), 13, "[0, 0, 0]");
  try {
    parse_scene(weightless + "  - {tilt: {axis: [0, 1, 0], rate: 5, max: 30}}\n", "scene.yaml");
    FAIL("a tilt of no gravity was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()), Contains("loads[0].tilt") && Contains("gravity is zero"));
  }
}

TEST_CASE(
    "loads through the step loop: free fall under a tilting gravity, a base following its "
    "record",
    "[drivers][loads]") {
  // A free block: its velocity is ∫g(t)dt; with g turning at ω from −z about +y,
  // v_x(t) = −g(1 − cos ωt)/ω and v_z(t) = −g sin(ωt)/ω.
  Scene s = block_scene(0.2);
  s.gravity = Vec3(0, 0, -10);
  LoadSpec tilt;
  tilt.kind = LoadSpec::Kind::tilt;
  tilt.tilt.rate = 2.0;
  tilt.tilt.max = 10.0;
  s.loads.push_back(tilt);
  auto sim = quiet(s);
  CHECK(sim->plan().gravity);
  while (sim->time() < 0.2 - 1e-12) sim->step();
  // Stored velocities are half-step values: v(t − dt/2).
  const double t = sim->time() - 0.5 * sim->time_step(), w = 2.0;
  const Vec3 v = piece_motions(sim->model())[0].velocity;
  CHECK(v.x() == Approx(-10 * (1 - std::cos(w * t)) / w).epsilon(1e-3));
  CHECK(v.z() == Approx(-10 * std::sin(w * t) / w).epsilon(1e-3));
  CHECK(sim->energy().balance_error() < 1e-3);

  // A body with a base motion moves with the record's velocity (all components prescribed).
  Scene b = block_scene(0.1);
  LoadSpec base;
  base.kind = LoadSpec::Kind::base_motion;
  base.bodies = {0};
  base.base_motion.time = {0.0, 0.1};
  base.base_motion.acceleration = {0.0, 1.0};
  base.base_motion.direction = Vec3(0, 1, 0);
  base.base_motion.scale = 9.81;
  b.loads.push_back(base);
  auto moving = quiet(b);
  CHECK(moving->plan().kinematic_loads);
  double y0 = piece_motions(moving->model())[0].centroid.y();
  while (moving->time() < 0.08 - 1e-12) moving->step();
  const double tm = moving->time() - 0.5 * moving->time_step();
  const PieceMotion m = piece_motions(moving->model())[0];
  CHECK(m.velocity.y() == Approx(9.81 * 5 * tm * tm).epsilon(1e-9));  // ∫ 9.81·10t dt
  CHECK(std::abs(m.velocity.x()) + std::abs(m.velocity.z()) < 1e-12);
  // Displacement: midpoint sums of the exact velocity, ≈ 9.81·(5/3)t³.
  const double T = moving->time();
  CHECK(m.centroid.y() - y0 == Approx(9.81 * 5.0 / 3.0 * T * T * T).epsilon(1e-3));
}

TEST_CASE("a prescribed velocity follows its time history, a later constant load keeps its nodes",
          "[drivers][loads]") {
  // The block's top nodes move along z with v·h(t), h a quintic step over [0, T]: their
  // displacement after t_end > T is v·(T/2 + t_end − T) (the step is symmetric about T/2); the
  // mid-step velocities make the sum the midpoint rule, exact to O(dt²).  The bottom nodes are
  // held by a constant load; a corner node is also held by a later constant load, which wins.
  const double dt = 1e-6, T = 20e-6, end = 40e-6, v = 1e-3;  // s, s, s, m/s
  Scene s = block_scene(end);
  s.time.auto_step = false;
  s.time.step = dt;
  LoadSpec top;
  top.region = RegionSpec{Vec3(-1, -1, 0.19), Vec3(1, 1, 1)};
  top.velocity = Vec3(0, 0, v);
  top.history = TimeHistory::smooth_step(0.0, T, 0.0, 1.0);
  LoadSpec bottom;
  bottom.region = RegionSpec{Vec3(-1, -1, -1), Vec3(1, 1, 0.01)};
  LoadSpec corner;  // the top corner at the origin's column, held along z only
  corner.region = RegionSpec{Vec3(-1, -1, 0.19), Vec3(0.01, 0.01, 1)};
  corner.dof_mask = 4;
  s.loads = {bottom, top, corner};
  auto sim = quiet(s);
  const NodeArrays& nodes = sim->model().nodes;
  int top_nodes = 0;
  for (LocalIndex n = 0; n < nodes.size(); ++n)  // at rest at t = 0: h(0) = 0
    if (nodes.x0(n)[2] > 0.19) CHECK(nodes.v[3 * n + 2] == 0.0);
  while (sim->time() < end - 0.5 * dt) sim->step();
  const double expected = v * (T / 2 + end - T);  // m
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    if (nodes.x0(n)[2] < 0.19) continue;
    const double uz = nodes.x[3 * n + 2] - nodes.x0(n)[2];
    if (nodes.x0(n)[0] < 0.01 && nodes.x0(n)[1] < 0.01) {
      CHECK(uz == 0.0);  // the corner load comes later in the scene
      continue;
    }
    ++top_nodes;
    CHECK(uz == Approx(expected).epsilon(1e-5));
    CHECK(nodes.v[3 * n + 2] == Approx(v).epsilon(1e-12));  // h = 1 after T
  }
  CHECK(top_nodes == 3);  // 2 × 2 corners of one cell, less the held one
}

TEST_CASE("loads_settle: when each kind of load stops changing", "[drivers][loads]") {
  const auto settle_of = [](LoadSpec load) {
    Scene s = block_scene(1.0);
    load.name = "l";
    s.loads = {load};
    return loads_settle(s.loads);
  };
  LoadSpec support;  // a prescribed velocity of zero: constant
  CHECK(settle_of(support).load == -1);
  CHECK(settle_of(support).time == 0.0);

  LoadSpec push;  // a constant velocity: the boundary never stops
  push.velocity = Vec3(0.01, 0, 0);
  CHECK(settle_of(push).moving);
  CHECK(settle_of(push).time == HUGE_VAL);
  push.history = TimeHistory::smooth_step(0.1, 0.3, 1.0, 0.0);  // slows to a stop at 0.3 s
  CHECK_FALSE(settle_of(push).moving);
  CHECK(settle_of(push).time == 0.3);
  push.history = TimeHistory::table({0.0, 0.2, 0.5, 0.9}, {0.0, 1.0, 0.0, 0.0});
  CHECK(settle_of(push).time == 0.5);  // its last change of value, not its last row
  push.history = TimeHistory::smooth_step(0.1, 0.3, 0.0, 1.0);  // then moves at 0.01 m/s
  CHECK(settle_of(push).moving);

  LoadSpec tilt;
  tilt.kind = LoadSpec::Kind::tilt;
  tilt.tilt.rate = 0.5;
  tilt.tilt.max = 0.2;
  tilt.tilt.start = 0.1;
  CHECK(settle_of(tilt).time == Approx(0.5));
  CHECK(describe_loads_settle(block_scene(1.0), LoadsSettle{}) == "no load changes");
  Scene named = block_scene(1.0);
  tilt.name = "table";
  named.loads = {support, tilt};
  const LoadsSettle t = loads_settle(named.loads);
  CHECK(t.load == 1);
  CHECK(describe_loads_settle(named, t) == "load 'table', a tilt, changes until t = 0.5 s");

  LoadSpec ramp;
  ramp.kind = LoadSpec::Kind::ramp;
  ramp.ramp.rate = 10.0;
  ramp.ramp.max = 2.0;
  ramp.ramp.start = 0.05;
  CHECK(settle_of(ramp).time == Approx(0.25));
  ramp.ramp.history = TimeHistory::table({0.0, 0.4}, {0.0, 3.0});
  CHECK(settle_of(ramp).time == 0.4);

  LoadSpec surface;
  surface.kind = LoadSpec::Kind::surface;
  CHECK(settle_of(surface).time == 0.0);
  surface.history = TimeHistory::smooth_step(0.0, 0.7, 0.0, 1.0);
  CHECK(settle_of(surface).time == 0.7);

  LoadSpec base;  // the ground moves uniformly after its record
  base.kind = LoadSpec::Kind::base_motion;
  base.base_motion.time = {0.0, 0.1, 0.6};
  base.base_motion.acceleration = {0.0, 1.0, 0.0};
  CHECK(settle_of(base).time == 0.6);
  CHECK_FALSE(settle_of(base).moving);
  // A record named by file: the schedule reads it once and counts it too.
  Scene from_file = block_scene(1.0);
  base.bodies = {0};
  base.base_motion.time.clear();
  base.base_motion.acceleration.clear();
  base.base_motion.file = temp_file("settle.csv", "0,0\n0.2,1\n0.7,0\n");
  from_file.loads = {base};
  auto sim = quiet(from_file);
  CHECK(sim->loads_settle().time == 0.7);
  CHECK(sim->loads_settle().load == 0);
}

TEST_CASE(
    "quasi_static.equilibrium_ratio ends a run only once its loads are constant: not before a "
    "ramp starts, not while it rises",
    "[drivers][loads][quasi_static]") {
  // The block held at its bottom face settles under local damping; a horizontal acceleration
  // ramp from 0.05 s to 0.07 s (2 m/s² at 100 m/s³) then loads it sideways.
  const auto run = [](bool with_ramp) {
    Scene s = block_scene(0.3);
    s.gravity = Vec3(0, 0, -9.81);
    s.quasi_static.local_damping = 0.8;
    s.quasi_static.equilibrium_ratio = 1e-3;
    LoadSpec bottom;
    bottom.region = RegionSpec{Vec3(-1, -1, -1), Vec3(1, 1, 0.01)};
    s.loads = {bottom};
    if (with_ramp) {
      LoadSpec ramp;
      ramp.kind = LoadSpec::Kind::ramp;
      ramp.ramp.rate = 100.0;
      ramp.ramp.max = 2.0;
      ramp.ramp.start = 0.05;
      s.loads.push_back(ramp);
    }
    auto sim = quiet(s);
    const RunReport report = sim->run();
    return std::make_tuple(report, sim->time(), sim->unbalanced_force_ratio(),
                           sim->loads_settle().time);
  };
  const auto [alone, alone_time, alone_ratio, alone_settle] = run(false);
  INFO("without the ramp: " << alone.reason);
  CHECK_THAT(alone.reason, Contains("equilibrium at step"));
  CHECK(alone_settle == 0.0);
  CHECK(alone_time < 0.05);  // settled before the ramp would start
  const auto [ramped, ramped_time, ramped_ratio, ramped_settle] = run(true);
  INFO("with the ramp: " << ramped.reason);
  CHECK(ramped_settle == Approx(0.07));
  CHECK_THAT(ramped.reason, Contains("equilibrium at step"));
  CHECK(ramped_time >= 0.07);  // it was below the ratio before, but the load was not all there
  CHECK(ramped_time < 0.3);
  CHECK(ramped_ratio < 1e-3);
}

TEST_CASE("a velocity load on a region that holds no node is refused, naming its key's line",
          "[drivers][loads]") {
  // A region beside the model held nothing and the run went on without its boundary condition.
  const std::string scene_text =
      "time: {end: 0.01}\n"
      "materials:\n"
      "  rock: {density: 2500, elastic: {young: 1.0e9, poisson: 0.25}}\n"
      "bodies:\n"
      "  - {name: block, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, material: rock}\n"
      "loads:\n"
      "  - {region: {box: {min: [0, 0, 0.99], max: [1, 1, 2]}}, velocity: [0, 0, -0.1]}\n"
      "  - {name: beside, region: {box: {min: [5, 5, 5], max: [6, 6, 6]}}, velocity: [0, 0, 1]}\n";
  const Scene scene = parse_scene(scene_text, "scene.yaml");
  CHECK_THROWS_WITH(quiet(scene), Contains("scene.yaml:8:") && Contains("loads[1].region") &&
                                      Contains("velocity load 'beside' holds no node") &&
                                      Contains("[5, 5, 5] .. [6, 6, 6] at t = 0"));
  Scene held = scene;  // the top face's region alone holds its four nodes
  held.loads.pop_back();
  CHECK_NOTHROW(quiet(held));
}
