// Joint laws as the engine builds them from a scene: the user-set penalty (and the advice when a
// penalty snaps back, checked by setting the value it names), and strengths drawn from a
// distribution — their sample statistics against the distribution's, and each joint's strength a
// function of its gid alone (any gid offset, any order).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "core/error.hpp"
#include "core/joint_strength.hpp"
#include "core/model_builder.hpp"
#include "core/state_hash.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;
using namespace fdem;

namespace {

// The rock: E = 10 GPa and energy_II = 20 J/m² with c = 20 MPa; the auto penalty (50 E)
// snaps back in shear at the 0.25 m cells' joint size.
std::string rock_scene(const std::string& fracture_extra, int cells = 4) {
  const std::string n = std::to_string(cells);
  return "time: {end: 1.0e-5}\n"
         "materials:\n"
         "  rock:\n"
         "    density: 2500\n"
         "    elastic: {young: 1.0e10, poisson: 0.25}\n"
         "    fracture: {tensile_strength: 5e6, cohesion: 2e7, friction_angle: 30, energy_I: 50, "
         "energy_II: 20" +
         fracture_extra +
         "}\n"
         "bodies:\n"
         "  - {name: block, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [" +
         n + ", " + n + ", " + n + "]}}, material: rock, joints: all}\n";
}

std::string build_error(const std::string& text) {
  try {
    builders::quiet_simulation(parse_scene(text, "rock.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The number after `marker` in `text`.
double number_after(const std::string& text, const std::string& marker) {
  const std::size_t at = text.find(marker);
  REQUIRE(at != std::string::npos);
  return std::strtod(text.c_str() + at + marker.size(), nullptr);
}

Model model_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  const Scene scene = parse_scene(text, "rock.yaml", overrides);
  return build_model(scene, load_body_meshes(scene));
}

// Each joint's tensile-strength factor (its law's f_t over the block's), by joint index.
std::vector<double> factors_by_index(const Model& m, double block_strength) {
  std::vector<double> f(m.joints.size());
  for (LocalIndex j = 0; j < m.joints.size(); ++j)
    f[static_cast<std::size_t>(m.joints.gid[j] - m.gid_offset)] =
        m.joint_laws[static_cast<std::size_t>(m.joints.law[j])].fracture.tensile_strength /
        block_strength;
  return f;
}

double mean_of(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double deviation_of(const std::vector<double>& v) {
  const double m = mean_of(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

}  // namespace

TEST_CASE("a joint penalty that snaps back: the error names the penalty that works", "[joints]") {
  const std::string message = build_error(rock_scene(""));
  INFO(message);
  CHECK_THAT(message, Contains("rock.yaml:6: materials.rock.fracture: the joints of material "
                               "'rock' cannot work with the joint penalty p_n = 5e+11 Pa (auto: "
                               "50·E)") &&
                          Contains("Shear would snap back") &&
                          Contains("set materials.rock.fracture.penalty: ") &&
                          Contains("or raise energy_II above"));
  const double advised = number_after(message, "set materials.rock.fracture.penalty: ");
  const double bound = number_after(message, "valid: any value above ");
  const double energy = number_after(message, "or raise energy_II above ");
  const double size = number_after(message, "stays below ");
  std::printf("  snap-back advice: penalty %g Pa (bound %g), energy_II > %g J/m², h < %g m\n",
              advised, bound, energy, size);
  CHECK(advised > bound);
  CHECK(advised < 1.1 * bound);
  // The advised value works; just under the stated bound does not.
  CHECK(build_error(rock_scene(", penalty: " + std::to_string(advised))).empty());
  CHECK_THAT(build_error(rock_scene(", penalty: " + std::to_string(0.995 * bound))),
             Contains("Shear would snap back"));
  // So does each other remedy it names: the energy, or a finer mesh.
  CHECK(build_error(rock_scene("").replace(rock_scene("").find("energy_II: 20"), 13,
                                           "energy_II: " + std::to_string(1.01 * energy)))
            .empty());
  // h scales as 1/cells: 4 cells give joints up to `now`; enough cells bring them below `size`.
  const double now = number_after(message, "(now up to ");
  const int cells = static_cast<int>(std::ceil(4.0 * now / size));
  CHECK(cells > 4);
  CHECK(build_error(rock_scene("", cells)).empty());
}

TEST_CASE("fdem check and fdem run refuse a snapping penalty alike", "[joints][cli]") {
  fdem_test::TempDir dir;
  fdem_test::write_text(dir / "rock.yaml", rock_scene(""));
  const fdem_test::Outcome check = fdem_test::run_fdem(dir, "check rock.yaml");
  const fdem_test::Outcome run = fdem_test::run_fdem(dir, "run rock.yaml -q -o out");
  CHECK(check.exit_code == 2);
  CHECK(run.exit_code == 2);
  CHECK_THAT(check.err, Contains("Shear would snap back"));
  CHECK_THAT(run.err, Contains("Shear would snap back"));
  fdem_test::write_text(dir / "ok.yaml", rock_scene(", penalty: 5e12"));
  CHECK(fdem_test::run_fdem(dir, "check ok.yaml").exit_code == 0);
}

TEST_CASE("a set penalty reaches every law, auto stays 50 E", "[joints]") {
  const Model automatic = model_of(rock_scene(", penalty: {tangential: 3e12}"));
  REQUIRE(!automatic.joint_laws.empty());
  for (const JointLawSpec& law : automatic.joint_laws) {
    CHECK(law.normal_penalty == 5e11);
    CHECK(law.tangential_penalty == 3e12);
    CHECK(law.auto_penalty == 5e11);
    CHECK(law.strength_scale == 1.0);
    CHECK(law.fracture.tensile_strength == 5e6);  // bit for bit the block's without a spread
  }
}

TEST_CASE("strength distribution: the joints' strengths have its mean and spread", "[joints]") {
  // 8³ cells: 5 760 interior faces.  Sampling errors (1σ) of the mean cov/√n ≤ 0.3 % and of the
  // deviation ≤ 1 % of it; the 1 % bins add under 0.3 % of spread.  Tolerances: 3σ.
  struct Case {
    std::string spec;
    double cov;
  };
  const double weibull_cov =
      std::sqrt(std::tgamma(1.0 + 2.0 / 5.0) / std::pow(std::tgamma(1.0 + 1.0 / 5.0), 2) - 1.0);
  for (const Case& c : {Case{"{type: normal, cov: 0.2, seed: 11}", 0.2},
                        Case{"{type: weibull, modulus: 5, seed: 11}", weibull_cov}}) {
    const Model m = model_of(rock_scene(", penalty: 4e12, strength_distribution: " + c.spec, 8));
    const std::vector<double> f = factors_by_index(m, 5e6);
    REQUIRE(f.size() == 5760);
    const double mean = mean_of(f), deviation = deviation_of(f);
    std::printf("  %s: %zu joints, %zu laws, mean %.4f, cov %.4f (exact 1, %.4f)\n", c.spec.c_str(),
                f.size(), m.joint_laws.size(), mean, deviation, c.cov);
    CHECK(mean == Approx(1.0).margin(3 * c.cov / std::sqrt(5760.0)));
    CHECK(deviation == Approx(c.cov).epsilon(0.04));
    // Cohesion gets the same factor as the tensile strength, joint by joint.
    for (const JointLawSpec& law : m.joint_laws)
      CHECK(law.fracture.cohesion / 2e7 == Approx(law.fracture.tensile_strength / 5e6));
  }
}

TEST_CASE("strength distribution: a joint's strength depends on its gid only", "[joints]") {
  const std::string text =
      rock_scene(", penalty: 4e12, strength_distribution: {type: weibull, modulus: 3, seed: 7}");
  const Model plain = model_of(text);
  const Model shifted = model_of(text, {"parallel.gid_offset=4294979641"});
  REQUIRE(shifted.gid_offset == 4294979641);
  const std::vector<double> f = factors_by_index(plain, 5e6);
  CHECK(f == factors_by_index(shifted, 5e6));
  CHECK(joint_strength_hash(plain) == joint_strength_hash(shifted));
  // The factor is the binned draw of (seed, joint index).
  const StrengthDistributionSpec& d = plain.joint_laws[0].fracture.strength_distribution;
  for (std::size_t i = 0; i < f.size(); ++i)
    CHECK(f[i] == Approx(strength_bin_factor(strength_bin(d, i))).epsilon(1e-14));
  // Another seed: another realisation, another fingerprint.
  const Model other = model_of(text, {"materials.rock.fracture.strength_distribution.seed=8"});
  CHECK(factors_by_index(other, 5e6) != f);
  CHECK(joint_strength_hash(other) != joint_strength_hash(plain));
}
