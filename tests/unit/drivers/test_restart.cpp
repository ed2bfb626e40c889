// Restart validation: a restart must continue the checkpoint's state with the scene that made it.
// time.end must lie after the checkpoint; changes to materials that shaped the state are refused;
// other changes are named by key as warnings.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>

#include "cli_test_support.hpp"

using Catch::Matchers::Contains;
using fdem_test::Outcome;
using fdem_test::run_fdem;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

// A block thrown onto a fixed base (contact, friction), checkpointed at t = 0.002 s and 0.004 s.
const char* thrown_block = R"(name: thrown-block
time: {end: 0.005}
gravity: [0, 0, -9.81]
materials:
  stone:
    density: 2500
    elastic: {young: 1.0e8, poisson: 0.2}
    contact: {friction: 0.6}
bodies:
  - {name: base, mesh: {box: {min: [0, 0, -0.1], max: [1, 0.2, 0], cells: [4, 1, 1]}},
     material: stone, fixed: true}
  - {name: block, mesh: {box: {min: [0.1, 0, 0.001], max: [0.3, 0.2, 0.2], cells: [1, 1, 1]}},
     material: stone, velocity: [5, 0, -1]}
output: {every: 0, checkpoint_every: 0.002}
)";

// Runs the scene once and returns the path (in `dir`) of its first checkpoint.
std::string first_checkpoint(const TempDir& dir) {
  write_text(dir / "scene.yaml", thrown_block);
  const Outcome o = run_fdem(dir, "run scene.yaml -o first -q");
  INFO(o.err);
  REQUIRE(o.exit_code == 0);
  std::string first;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "first"))
    if (entry.path().extension() == ".h5" && (first.empty() || entry.path().string() < first))
      first = entry.path().string();
  REQUIRE_FALSE(first.empty());
  return first;
}

}  // namespace

TEST_CASE("a restart refuses a time.end at or before the checkpoint's time", "[cli][restart]") {
  TempDir dir;
  const std::string checkpoint = first_checkpoint(dir);
  const Outcome o =
      run_fdem(dir, "run scene.yaml -o again -q --restart " + checkpoint + " --set time.end=0.001");
  INFO(o.err);
  CHECK(o.exit_code == 2);
  CHECK_THAT(o.err, Contains("time.end = 0.001 s is not after the time of the checkpoint"));
  CHECK_FALSE(std::filesystem::exists(dir / "again/summary.json"));
}

TEST_CASE("a restart refuses changed densities and elastic constants, naming the key",
          "[cli][restart]") {
  TempDir dir;
  const std::string checkpoint = first_checkpoint(dir);
  for (const char* change : {"materials.stone.density=2400", "materials.stone.elastic.young=2e8"}) {
    const Outcome o =
        run_fdem(dir, "run scene.yaml -o again -q --restart " + checkpoint + " --set " + change);
    INFO(change << ": " << o.err);
    CHECK(o.exit_code == 2);
    const std::string key = std::string(change).substr(0, std::string(change).find('='));
    CHECK_THAT(o.err, Contains("a restart cannot change: " + key + " changed from"));
  }
}

TEST_CASE("a restart lists other changes as warnings by key and continues", "[cli][restart]") {
  TempDir dir;
  const std::string checkpoint = first_checkpoint(dir);
  const Outcome same = run_fdem(dir, "run scene.yaml -o same -q --restart " + checkpoint);
  INFO(same.err);
  CHECK(same.exit_code == 0);
  CHECK_THAT(same.err, !Contains("warning"));

  const Outcome changed = run_fdem(
      dir, "run scene.yaml -o changed -q --restart " + checkpoint +
               " --set bodies.1.velocity=[9,0,0] --set materials.stone.contact.friction=0.3"
               " --set gravity=[0,0,-5]");
  INFO(changed.err);
  CHECK(changed.exit_code == 0);
  CHECK_THAT(changed.err,
             Contains("warning: restart: bodies.block.velocity.x changed from 5 to 9 is ignored"));
  CHECK_THAT(changed.err, Contains("materials.stone.contact.friction changed from 0.6 to 0.3 "
                                   "applies from the checkpoint's time on"));
  CHECK_THAT(changed.err, Contains("gravity.z changed from -9.81 to -5"));
  // The quasi-static mode (its keys listed only while it is on; 0 local, 1 kinetic damping).
  const Outcome settled = run_fdem(dir, "run scene.yaml -o settled -q --restart " + checkpoint +
                                            " --set quasi_static.damping=kinetic");
  INFO(settled.err);
  CHECK(settled.exit_code == 0);
  CHECK_THAT(settled.err, Contains("quasi_static.damping (new, 1) applies from the checkpoint's "
                                   "time on"));
}

TEST_CASE("a restart warns when the contact law changes, auto's choice included",
          "[cli][restart]") {
  TempDir dir;
  const std::string checkpoint = first_checkpoint(dir);  // dynamic: potential contact
  const std::string restart = " -q --restart " + checkpoint;
  const Outcome corners =
      run_fdem(dir, "run scene.yaml -o corners" + restart + " --set contact.formulation=corners");
  INFO(corners.err);
  CHECK(corners.exit_code == 0);
  CHECK_THAT(corners.err, Contains("contact.corners (new, 1) applies from the checkpoint's time"));
  // Quasi-static from the restart on: auto turns to corner contact, and says so.
  const Outcome quasi_static = run_fdem(
      dir, "run scene.yaml -o quasi_static" + restart + " --set quasi_static.local_damping=0.8");
  INFO(quasi_static.err);
  CHECK(quasi_static.exit_code == 0);
  CHECK_THAT(quasi_static.err, Contains("contact.corners (new, 1)"));
}

TEST_CASE("a restart refuses a changed initial stress and warns of new absorbing faces",
          "[cli][restart]") {
  TempDir dir;
  const std::string checkpoint = first_checkpoint(dir);
  const Outcome stressed =
      run_fdem(dir, "run scene.yaml -o stressed -q --restart " + checkpoint +
                        " --set 'initial_stress=[{uniform: [0, 0, -1e4, 0, 0, 0]}]'");
  CHECK(stressed.exit_code == 2);
  CHECK_THAT(stressed.err, Contains("a restart cannot change: initial_stress[0].") &&
                               Contains("initial_stress[0].kind (new, 1)"));
  const Outcome absorbing = run_fdem(
      dir, "run scene.yaml -o absorbing -q --restart " + checkpoint +
               " --set 'absorbing=[{region: {box: {min: [-1, -1, -0.11], max: [2, 1, -0.09]}}}]'");
  INFO(absorbing.err);
  CHECK(absorbing.exit_code == 0);
  CHECK_THAT(absorbing.err, Contains("absorbing[0].region.box.min.z (new, -0.11) applies from the "
                                     "checkpoint's time on"));
}
