// The `fdem` command's advice about the contact formulation, the sliding of undamped bodies, a
// fixed step above the critical one, a contact penalty far below E and friction on only one of two
// touching materials: what `fdem check` prints for a scene, and what a numerical failure says;
// what it says of a quasi-static run that equilibrium_ratio may end; and the warning of `fdem run`
// about bodies overlapping at t = 0; and its warning of a ground that moves while the quasi-static
// damping acts.
#include <catch2/catch.hpp>
#include <string>

#include "cli_test_support.hpp"

using Catch::Matchers::Contains;
using fdem_test::critical_step_from_check;
using fdem_test::format_g;
using fdem_test::Outcome;
using fdem_test::read_text;
using fdem_test::run_fdem;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

// A block resting on a fixed base, with friction and no element damping.
const char* block_on_base = R"(name: block-on-base
time: {end: 0.05}
gravity: [0, 0, -9.81]
materials:
  soft:
    density: 1000
    elastic: {young: 1.0e6, poisson: 0.25}
    contact: {friction: 0.5}
bodies:
  - name: base
    mesh: {box: {min: [-1, -1, -0.2], max: [1, 1, 0], cells: [2, 2, 1]}}
    material: soft
    fixed: true
  - name: block
    mesh: {box: {min: [-0.2, -0.2, 0], max: [0.2, 0.2, 0.2], cells: [1, 1, 1]}}
    material: soft
output:
  every: 0.01
)";

}  // namespace

TEST_CASE("fdem check advises potential contact for dynamic runs under corner contact", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", block_on_base);
  const std::string advice = "advice: contact.formulation: corners is made for quasi-static holds";
  const Outcome o = run_fdem(dir, "check scene.yaml --set contact.formulation=corners");
  CHECK(o.exit_code == 0);
  CHECK_THAT(o.out, Contains(advice));
  CHECK_THAT(run_fdem(dir, "check scene.yaml").out, !Contains(advice));
  write_text(dir / "qs.yaml", std::string(block_on_base) +
                                  "quasi_static: {local_damping: 0.8}\ncontact: {formulation: "
                                  "corners}\n");
  CHECK_THAT(run_fdem(dir, "check qs.yaml").out, !Contains(advice));
}

TEST_CASE("fdem check says which contact formulation auto chose", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", block_on_base);
  write_text(dir / "qs.yaml", std::string(block_on_base) + "quasi_static: {local_damping: 0.8}\n");
  CHECK_THAT(run_fdem(dir, "check scene.yaml").out,
             Contains("formulation potential (auto: potential unless quasi-static"));
  CHECK_THAT(run_fdem(dir, "check qs.yaml").out,
             Contains("formulation corners (auto: quasi-static throughout, no joints)"));
  CHECK_THAT(run_fdem(dir, "check qs.yaml --set quasi_static.until=0.005").out,
             Contains("formulation potential (auto"));
  const std::string chosen = run_fdem(dir, "check qs.yaml --set contact.formulation=potential").out;
  CHECK_THAT(chosen, Contains("formulation potential\n"));
}

TEST_CASE("a numerical failure under corner contact says how auto chose it", "[cli]") {
  TempDir dir;
  write_text(dir / "qs.yaml", std::string(block_on_base) + "quasi_static: {local_damping: 0.8}\n");
  const double critical = critical_step_from_check(run_fdem(dir, "check qs.yaml").out);
  REQUIRE(critical > 0.0);
  const std::string step = " --set time.step=" + format_g(3.0 * critical);
  const Outcome automatic = run_fdem(dir, "run qs.yaml -q -o out" + step);
  CHECK(automatic.exit_code == 3);
  CHECK_THAT(automatic.err, Contains("Under corner contact (contact.formulation: auto, as in every "
                                     "run quasi-static throughout without joints)"));
  const Outcome potential =
      run_fdem(dir, "run qs.yaml -q -o out2 --set contact.formulation=potential" + step);
  CHECK(potential.exit_code == 3);
  CHECK_THAT(potential.err, !Contains("corner contact"));
}

TEST_CASE("fdem check advises element damping for sliding bodies with friction", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", block_on_base);
  const std::string advice =
      "advice: material 'soft' has friction and no element damping: a body of it that slides";
  const Outcome o = run_fdem(dir, "check scene.yaml");
  CHECK(o.exit_code == 0);
  CHECK_THAT(o.out, Contains(advice));
  CHECK_THAT(o.out, Contains("docs/verification.md, \"Sliding too fast\""));
  SECTION("not with element damping") {
    const Outcome d = run_fdem(dir, "check scene.yaml --set materials.soft.damping=0.3");
    CHECK(d.exit_code == 0);
    CHECK_THAT(d.out, !Contains("advice:"));
  }
  SECTION("not without friction") {
    const Outcome f = run_fdem(dir, "check scene.yaml --set materials.soft.contact.friction=0");
    CHECK(f.exit_code == 0);
    CHECK_THAT(f.out, !Contains("advice:"));
  }
  SECTION("not under local damping for the whole run, but when it ends before") {
    write_text(dir / "qs.yaml",
               std::string(block_on_base) + "quasi_static: {local_damping: 0.8}\n");
    CHECK_THAT(run_fdem(dir, "check qs.yaml").out, !Contains("advice:"));
    write_text(dir / "settle.yaml",
               std::string(block_on_base) + "quasi_static: {local_damping: 0.8, until: 0.01}\n");
    CHECK_THAT(run_fdem(dir, "check settle.yaml").out, Contains(advice));
  }
}

TEST_CASE(
    "fdem check says from when quasi_static.equilibrium_ratio can end a run, or that it cannot",
    "[cli]") {
  TempDir dir;
  const std::string qs =
      std::string(block_on_base) + "quasi_static: {local_damping: 0.8, equilibrium_ratio: 1e-4}\n";
  write_text(dir / "qs.yaml", qs);
  CHECK_THAT(run_fdem(dir, "check qs.yaml").out,
             Contains("quasi-static: local damping 0.8 for the whole run; equilibrium_ratio 0.0001 "
                      "ends the run at equilibrium\n"));
  write_text(dir / "kinetic.yaml",
             std::string(block_on_base) + "quasi_static: {damping: kinetic, until: 0.02}\n");
  CHECK_THAT(run_fdem(dir, "check kinetic.yaml").out,
             Contains("quasi-static: kinetic damping until 0.02 s\n"));
  CHECK_THAT(run_fdem(dir, "check kinetic.yaml --set quasi_static.local_damping=0.1").out,
             Contains("quasi-static: kinetic damping and local damping 0.1 until 0.02 s\n"));
  // A tilt of 2° at 100°/s from 0.01 s is all there at 0.03 s; 10° only at 0.11 s, after the end.
  write_text(dir / "tilt.yaml",
             qs + "loads:\n  - {tilt: {axis: [0, 1, 0], rate: 100, max: 2, start: "
                  "0.01}}\n");
  CHECK_THAT(run_fdem(dir, "check tilt.yaml").out,
             Contains("equilibrium_ratio 0.0001 ends the run at equilibrium from t = 0.03 s on "
                      "(loads[0], a tilt, changes until t = 0.03 s)"));
  std::string late_tilt = read_text(dir / "tilt.yaml");
  late_tilt.replace(late_tilt.find("max: 2,"), 7, "max: 10,");
  write_text(dir / "late.yaml", late_tilt);
  const Outcome late = run_fdem(dir, "check late.yaml");
  CHECK(late.exit_code == 0);
  CHECK_THAT(late.out, Contains("note: quasi_static.equilibrium_ratio cannot end this run: "
                                "loads[0], a tilt, changes until t = 0.11 s"));
  CHECK_THAT(run_fdem(dir, "check tilt.yaml --set quasi_static.until=0.02").out,
             Contains("cannot end this run: loads[0], a tilt, changes until t = 0.03 s, and the "
                      "run ends at equilibrium only once every load is constant, while the damping "
                      "acts"));
}

TEST_CASE("fdem check advises against a fixed step above the critical one", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", block_on_base);
  const Outcome automatic = run_fdem(dir, "check scene.yaml");
  const double critical = critical_step_from_check(automatic.out);
  REQUIRE(critical > 0.0);
  CHECK_THAT(automatic.out, !Contains("advice: time.step"));
  const Outcome above = run_fdem(dir, "check scene.yaml --set time.step=" + format_g(2 * critical));
  CHECK(above.exit_code == 0);
  CHECK_THAT(above.out, Contains("advice: time.step is 2 x the critical step") &&
                            Contains("use time.step: auto or a step below"));
  CHECK_THAT(run_fdem(dir, "check scene.yaml --set time.step=" + format_g(0.5 * critical)).out,
             !Contains("advice: time.step"));
}

TEST_CASE("fdem run and fdem check warn when bodies overlap at t = 0, not when they touch",
          "[cli]") {
  // The block sunk 5 cm into the base is thrown off it by the penalty; resting on it, nothing.
  TempDir dir;
  std::string sunk = block_on_base;
  sunk.replace(sunk.find("min: [-0.2, -0.2, 0]"), 20, "min: [-0.2, -0.2, -0.05]");
  write_text(dir / "sunk.yaml", sunk);
  write_text(dir / "resting.yaml", block_on_base);
  const Outcome thrown = run_fdem(dir, "run sunk.yaml -o out1 --set time.end=1e-3");
  CHECK(thrown.exit_code == 0);
  CHECK_THAT(thrown.err,
             Contains("fdem: warning: bodies overlap at t = 0: their contact energy is") &&
                 Contains("place the bodies apart or exactly touching"));
  const Outcome resting = run_fdem(dir, "run resting.yaml -o out2 --set time.end=1e-3");
  CHECK(resting.exit_code == 0);
  CHECK_THAT(resting.err, !Contains("warning: bodies overlap"));
  // `fdem check` takes the first step too.
  const Outcome checked = run_fdem(dir, "check sunk.yaml");
  CHECK(checked.exit_code == 0);
  CHECK_THAT(checked.err, Contains("fdem: warning: bodies overlap at t = 0"));
  CHECK_THAT(run_fdem(dir, "check resting.yaml").err, !Contains("warning: bodies overlap"));
}

TEST_CASE("fdem check advises against a contact penalty far below E", "[cli]") {
  // E = 1 MPa: a penalty of 100 Pa (1e-4 E) lets the block sink through its base.
  TempDir dir;
  write_text(dir / "scene.yaml", block_on_base);
  const std::string advice = "advice: material 'soft' has a contact penalty of";
  CHECK_THAT(run_fdem(dir, "check scene.yaml").out, !Contains(advice));
  CHECK_THAT(run_fdem(dir, "check scene.yaml --set materials.soft.contact.penalty=100").out,
             Contains(advice + std::string(" 0.0001 x its E (100 Pa against 1e+06 Pa)")) &&
                 Contains("the default (auto) is 10 E"));
  CHECK_THAT(run_fdem(dir, "check scene.yaml --set materials.soft.contact.penalty=1e5").out,
             !Contains(advice));
}

TEST_CASE("fdem check says when only one of two touching materials has friction", "[cli]") {
  // The block's material has friction, the base's none: their contact takes the smaller, 0.
  TempDir dir;
  std::string mixed = block_on_base;
  mixed.replace(mixed.find("materials:\n"), 11,
                "materials:\n  bare:\n    density: 1000\n    elastic: {young: 1.0e6, poisson: "
                "0.25}\n");
  mixed.replace(mixed.find("material: soft\n    fixed: true"), 14, "material: bare");
  write_text(dir / "mixed.yaml", mixed);
  write_text(dir / "scene.yaml", block_on_base);
  const std::string advice =
      "advice: contact between materials 'soft' (friction 0.5) and 'bare' (none) is frictionless: "
      "a pair takes the smaller coefficient; give 'bare' a friction too";
  const Outcome o = run_fdem(dir, "check mixed.yaml");
  INFO(o.out << o.err);
  CHECK(o.exit_code == 0);
  CHECK_THAT(o.out, Contains(advice));
  CHECK_THAT(run_fdem(dir, "check scene.yaml").out, !Contains("is frictionless"));
}

TEST_CASE("fdem check warns when the ground moves while the quasi-static damping acts", "[cli]") {
  TempDir dir;
  // The base moves with a record that is at rest until 0.02 s.
  write_text(dir / "ground.csv", "time,acceleration\n0,0\n0.02,0\n0.03,1\n0.04,0\n");
  write_text(dir / "scene.yaml", std::string(block_on_base) +
                                     "loads:\n  - {name: quake, bodies: [base], base_motion: "
                                     "{file: ground.csv, direction: [1, 0, 0]}}\n"
                                     "quasi_static: {local_damping: 0.8}\n");
  const std::string warning =
      "warning: the ground moves from t = 0.02 s (load 'quake', a base "
      "motion) while the quasi-static damping acts";
  const Outcome whole = run_fdem(dir, "check scene.yaml");
  INFO(whole.out << whole.err);
  REQUIRE(whole.exit_code == 0);
  CHECK_THAT(whole.out, Contains(warning));
  CHECK_THAT(whole.out, Contains("(quasi_static.until <= 0.02)"));
  CHECK_THAT(run_fdem(dir, "check scene.yaml --set quasi_static.damping=kinetic").out,
             Contains(warning));
  // Settled before the record starts: no warning.
  const Outcome settled = run_fdem(dir, "check scene.yaml --set quasi_static.until=0.02");
  REQUIRE(settled.exit_code == 0);
  CHECK_THAT(settled.out, Contains("quasi-static: local damping 0.8 until 0.02 s"));
  CHECK_THAT(settled.out, !Contains("warning: the ground moves"));
}
