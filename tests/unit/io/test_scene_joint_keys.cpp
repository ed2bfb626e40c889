// The fracture block's joint keys: `penalty` (auto | Pa | {normal, tangential}) and
// `strength_distribution` (none | weibull | normal, with a seed) — read into the scene, defaults
// when absent, and errors that name the key and the valid range.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using fdem::StrengthDistributionSpec;

namespace {

// A jointed rock box and an interface to a second box; `extra` goes into the rock's fracture
// block (line 6), `interface_extra` into the interface's (line 12).
std::string scene_with(const std::string& extra, const std::string& interface_extra = "") {
  return "time: {end: 0.1}\n"
         "materials:\n"
         "  rock:\n"
         "    density: 2500\n"
         "    elastic: {young: 1.0e10, poisson: 0.25}\n"
         "    fracture: {tensile_strength: 1e6, cohesion: 2e6, friction_angle: 30, energy_I: 10, "
         "energy_II: 50" +
         extra +
         "}\n"
         "bodies:\n"
         "  - {name: a, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, material: rock, joints: "
         "all}\n"
         "  - {name: b, mesh: {box: {min: [1, 0, 0], max: [2, 1, 1]}}, material: rock}\n"
         "interfaces:\n"
         "  - between: [a, b]\n"
         "    fracture: {tensile_strength: 1e5, cohesion: 2e5, friction_angle: 30, energy_I: 1, "
         "energy_II: 5" +
         interface_extra + "}\n";
}

fdem::Scene parse(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return fdem::parse_scene(text, "scene.yaml", overrides);
}

std::string input_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse(text, overrides);
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("joint keys absent: auto penalties, no strength distribution", "[io][joints]") {
  const fdem::Scene s = parse(scene_with(""));
  const fdem::FractureSpec& f = *s.materials[0].fracture;
  CHECK(f.normal_penalty == 0.0);  // 0: auto
  CHECK(f.tangential_penalty == 0.0);
  CHECK(f.strength_distribution.type == StrengthDistributionSpec::Type::none);
  CHECK(f.key == "materials.rock.fracture");
  CHECK(f.location == "scene.yaml:6");
  CHECK(s.interfaces[0].fracture.key == "interfaces[0].fracture");
  CHECK(s.interfaces[0].fracture.location == "scene.yaml:12");
  // `auto` and type none are the same as absent.
  const fdem::Scene same =
      parse(scene_with(", penalty: auto, strength_distribution: {type: none}"));
  CHECK(same.materials[0].fracture->normal_penalty == 0.0);
  CHECK(same.materials[0].fracture->tangential_penalty == 0.0);
  CHECK(same.materials[0].fracture->strength_distribution.type ==
        StrengthDistributionSpec::Type::none);
}

TEST_CASE("penalty: one value for both, or normal and tangential apart", "[io][joints]") {
  const fdem::Scene one = parse(scene_with(", penalty: 2.5e12"));
  CHECK(one.materials[0].fracture->normal_penalty == 2.5e12);
  CHECK(one.materials[0].fracture->tangential_penalty == 2.5e12);
  const fdem::Scene two = parse(
      scene_with(", penalty: {normal: 3e12, tangential: auto}", ", penalty: {tangential: 1e11}"));
  CHECK(two.materials[0].fracture->normal_penalty == 3e12);
  CHECK(two.materials[0].fracture->tangential_penalty == 0.0);
  CHECK(two.interfaces[0].fracture.normal_penalty == 0.0);
  CHECK(two.interfaces[0].fracture.tangential_penalty == 1e11);
  // --set reaches it like any key.
  const fdem::Scene set = parse(scene_with(""), {"materials.rock.fracture.penalty=7e11"});
  CHECK(set.materials[0].fracture->normal_penalty == 7e11);
  CHECK(set.materials[0].fracture->tangential_penalty == 7e11);
}

TEST_CASE("strength_distribution: weibull and normal with their seed", "[io][joints]") {
  const fdem::Scene w = parse(
      scene_with(", strength_distribution: {type: weibull, modulus: 6, seed: 17}",
                 ", strength_distribution: {type: normal, cov: 0.2, seed: 9007199254740991}"));
  const StrengthDistributionSpec& d = w.materials[0].fracture->strength_distribution;
  CHECK(d.type == StrengthDistributionSpec::Type::weibull);
  CHECK(d.modulus == 6.0);
  CHECK(d.seed == 17u);
  const StrengthDistributionSpec& n = w.interfaces[0].fracture.strength_distribution;
  CHECK(n.type == StrengthDistributionSpec::Type::normal);
  CHECK(n.cov == 0.2);
  CHECK(n.seed == 9007199254740991u);  // 2^53 − 1
}

TEST_CASE("joint keys out of range: the key, the value and what is valid", "[io][joints]") {
  const auto error = [](const std::string& extra) { return input_error(scene_with(extra)); };
  CHECK_THAT(error(", penalty: -1e9"),
             StartsWith("scene.yaml:6:") && Contains("materials.rock.fracture.penalty: -1e+09 "
                                                     "is impossible: the joint penalty (Pa, or "
                                                     "'auto' = 50 E) must be > 0"));
  CHECK_THAT(error(", penalty: {normal: 1e12, shear: 1e12}"),
             Contains("materials.rock.fracture.penalty.shear: unknown key 'shear'") &&
                 Contains("normal, tangential"));
  CHECK_THAT(error(", strength_distribution: {type: weibull, modulus: 0.5, seed: 1}"),
             Contains("strength_distribution.modulus: 0.5 is impossible: the Weibull modulus "
                      "must be >= 1"));
  CHECK_THAT(error(", strength_distribution: {type: normal, cov: 0.4, seed: 1}"),
             Contains("strength_distribution.cov: 0.4 is too large: cov must be in (0, 0.3]"));
  CHECK_THAT(error(", strength_distribution: {type: normal, cov: 0.2}"),
             Contains("strength_distribution.seed: missing required key 'seed'"));
  CHECK_THAT(error(", strength_distribution: {type: weibull, cov: 0.2, seed: 1}"),
             Contains("strength_distribution.cov: unknown key 'cov'"));
  CHECK_THAT(error(", strength_distribution: {type: gaussian, seed: 1}"),
             Contains("strength_distribution.type: 'gaussian' is not valid") &&
                 Contains("none, weibull, normal"));
  CHECK_THAT(error(", strength_distribution: {type: normal, cov: 0.1, seed: -3}"),
             Contains("strength_distribution.seed: -3 is impossible: the seed is an integer >= 0 "
                      "and < 2^53"));
  // A mapping without 'type' (a missing key, not a yaml-cpp exception; found by fuzzing).
  CHECK_THAT(error(", strength_distribution: {modulus: 3, seed: 1}"),
             Contains("strength_distribution.type: missing; expected a text value"));
  CHECK_THAT(error(", strength_distribution: weibull"),
             Contains("strength_distribution: expected {type: weibull, modulus: m, seed: s}"));
}
