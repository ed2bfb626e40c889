// Limits between a valid scene and a runnable one (drivers/run_limits): `fdem check` and `run`
// refuse, before allocating, what would exhaust memory or need absurd step counts, and naming
// the key to change.
#include <catch2/catch.hpp>
#include <string>

#include "cli_test_support.hpp"

using Catch::Matchers::Contains;
using fdem_test::Outcome;
using fdem_test::run_fdem;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

// A 1 m cube of 2×2×2 cells and a second one on top of it (contact between them).
const char* two_blocks = R"(name: two-blocks
time: {end: 0.01}
materials:
  rock:
    density: 2500
    elastic: {young: 1.0e9, poisson: 0.25}
bodies:
  - {name: base, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2]}}, material: rock}
  - {name: top, mesh: {box: {min: [0, 0, 1], max: [1, 1, 2], cells: [2, 2, 2]}}, material: rock}
output: {every: 0.005}
)";

const char* wall = R"(name: wall
time: {end: 0.01}
materials:
  brick: {density: 1800, elastic: {young: 5.0e9, poisson: 0.2}}
bodies:
  - {name: wall, material: brick,
     mesh: {wall: {unit: [0.2, 0.1, 0.05], courses: 4, units_per_course: 3}}}
)";

Outcome run_with(const std::string& scene, const std::string& args) {
  TempDir dir;
  write_text(dir / "scene.yaml", scene);
  return run_fdem(dir, args);
}

}  // namespace

TEST_CASE("a mesh too large for the memory per rank is refused before it is generated",
          "[cli][limits]") {
  SECTION("2e9 x 2e9 x 2 cells (the cell count overflows an int)") {
    for (const char* command : {"check", "run"}) {
      const Outcome o =
          run_with(two_blocks, std::string(command) +
                                   " scene.yaml --set bodies.0.mesh.box.cells=[2000000000,"
                                   "2000000000,2]");
      INFO(o.err);
      CHECK(o.exit_code == 2);
      CHECK_THAT(o.err, Contains("limits.max_memory_per_rank"));
      CHECK_THAT(o.err, Contains("48000000000000000000 tetrahedra") || Contains("4.8e+19"));
    }
  }
  SECTION("300^3 cells under a 4 GB limit") {
    const Outcome o = run_with(two_blocks,
                               "run scene.yaml --set bodies.0.mesh.box.cells=[300,300,300] "
                               "--set limits.max_memory_per_rank=4e9");
    INFO(o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("162000048 tetrahedra"));
    CHECK_THAT(o.err, Contains("more than limits.max_memory_per_rank = 4 GB"));
  }
  SECTION("more tets than one rank can index, with memory to spare") {
    // 640^3 cells: 1.57e9 tets; a 1 PB ceiling lets the memory check pass.
    const std::string cells = " --set bodies.0.mesh.box.cells=[640,640,640]";
    const Outcome o =
        run_with(two_blocks, "check scene.yaml --set limits.max_memory_per_rank=1e15" + cells);
    INFO(o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("more than the 238609294 one rank can index") &&
                          Contains("Run on more ranks"));
  }
  SECTION("a wall of 2147483647 courses") {
    const Outcome o =
        run_with(wall, "check scene.yaml --set bodies.0.mesh.wall.courses=2147483647");
    INFO(o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("limits.max_memory_per_rank"));
  }
  SECTION("the ceiling is the scene's to raise") {
    const Outcome o = run_with(two_blocks, "check scene.yaml --set limits.max_memory_per_rank=1e6");
    CHECK(o.exit_code == 2);
    const Outcome ok =
        run_with(two_blocks, "check scene.yaml --set limits.max_memory_per_rank=1e9");
    INFO(ok.err);
    CHECK(ok.exit_code == 0);
    CHECK_THAT(ok.out, Contains("memory: about"));
  }
}

TEST_CASE("a run needing more steps than limits.max_steps is refused with what sets the step",
          "[cli][limits]") {
  SECTION("time.end = 1e300 (the step count does not fit an integer)") {
    for (const char* command : {"check", "run"}) {
      const Outcome o =
          run_with(two_blocks,
                   std::string(command) + " scene.yaml --set time.end=1e300 --set output.every=0");
      INFO(o.out << o.err);
      CHECK(o.exit_code == 2);
      CHECK_THAT(o.err, Contains("limits.max_steps"));
      CHECK_THAT(o.out + o.err, !Contains("-9223372036854775808"));
      CHECK_THAT(o.out + o.err, !Contains("completed"));
    }
  }
  SECTION("a 1e-12 m tall body: the element that sets the step is named") {
    const Outcome o =
        run_with(two_blocks, "check scene.yaml --set bodies.1.mesh.box.max=[1,1,1.000000000001]");
    INFO(o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("limits.max_steps"));
    CHECK_THAT(o.err, Contains("of body 'top' (smallest height"));
  }
  SECTION("a contact penalty of 1e20 Pa: the contact bound is named; the limit can be raised") {
    const std::string stiff =
        "check scene.yaml --set time.end=1 --set 'materials.rock.contact={penalty: 1e20}'";
    const Outcome o = run_with(two_blocks, stiff);
    INFO(o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("contact penalties rock 1e+20 Pa"));
    const Outcome raised = run_with(two_blocks, stiff + " --set limits.max_steps=1e12");
    INFO(raised.err);
    CHECK(raised.exit_code == 0);
    CHECK_THAT(raised.out, Contains("(limit 1e+12)"));
  }
  SECTION("limits.max_steps must be positive") {
    const Outcome o = run_with(two_blocks, "check scene.yaml --set limits.max_steps=0");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("limits.max_steps: 0 is impossible"));
  }
}

TEST_CASE("output intervals that cannot advance time are refused, short ones do not loop",
          "[cli][limits]") {
  for (const char* key : {"every", "energy_every", "checkpoint_every"}) {
    const Outcome o =
        run_with(two_blocks, std::string("check scene.yaml --set output.") + key + "=1e-300");
    INFO(key << ": " << o.err);
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains(std::string("output.") + key + ": 1e-300 s cannot advance time"));
  }
  // 1e-14 s is allowed (1e-12 of time.end) and 1e10 times shorter than the step: a run must
  // skip the intervals within a step at once, not one by one.
  const Outcome o = run_with(two_blocks,
                             "run scene.yaml -q --set output.every=1e-14 "
                             "--set output.energy_every=1e-14 --set time.end=0.01");
  INFO(o.err);
  CHECK(o.exit_code == 0);
}

TEST_CASE(
    "a time step far above the mesh's stable step is stopped at once by the minimum-step "
    "guard",
    "[cli][limits]") {
  TempDir dir;
  write_text(dir / "scene.yaml", wall);
  // One unit: no contact, so the critical step is the elastic one.
  const std::string one_unit =
      " --set bodies.0.mesh.wall.units_per_course=1 --set bodies.0.mesh.wall.courses=1";
  const Outcome check = run_fdem(dir, "check scene.yaml" + one_unit);
  REQUIRE(check.exit_code == 0);
  const std::string needle = "critical ";
  const auto at = check.out.find(needle);
  REQUIRE(at != std::string::npos);
  const double critical = std::stod(check.out.substr(at + needle.size()));
  const Outcome o = run_fdem(
      dir, "run scene.yaml -q -o out --set time.step=" + std::to_string(4.0 * critical) + one_unit);
  INFO(o.err);
  CHECK(o.exit_code == 3);
  CHECK_THAT(o.err, Contains("numerical failure at step 0 "));
  CHECK_THAT(o.err, Contains("below half the time step (minimum-step guard), set by tetrahedron"));
  CHECK_THAT(o.err, Contains("of body 'wall'"));
  CHECK_THAT(o.err, Contains("use time.step: auto or a step below"));
}
