// Scene keys `absorbing:` and `initial_stress:`: read into the scene, errors naming the key and
// what is valid.
#include <catch2/catch.hpp>
#include <string>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;

namespace {

std::string scene_with(const std::string& extra, const std::string& gravity = "[0, 0, -9.81]") {
  return "time: {end: 0.1}\n"
         "gravity: " +
         gravity +
         "\n"
         "materials:\n"
         "  soil: {density: 1800, elastic: {young: 5.0e7, poisson: 0.3}}\n"
         "bodies:\n"
         "  - {name: a, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, material: soil}\n"
         "  - {name: b, mesh: {box: {min: [2, 0, 0], max: [3, 1, 1]}}, material: soil}\n" +
         extra;
}

std::string error(const std::string& text) {
  try {
    fdem::parse_scene(text, "scene.yaml");
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("initial_stress: uniform and geostatic entries per body", "[io][initial_stress]") {
  const fdem::Scene s =
      fdem::parse_scene(scene_with("initial_stress:\n"
                                   "  - {uniform: [-1e5, -2e5, -3e5, 1, 2, 3], bodies: [b]}\n"
                                   "  - {geostatic: {surface: 1.0, k0: 0.5}, bodies: [a]}\n"),
                        "scene.yaml");
  REQUIRE(s.initial_stress.size() == 2);
  CHECK(s.initial_stress[0].kind == fdem::InitialStressSpec::Kind::uniform);
  CHECK(s.initial_stress[0].stress[2] == -3e5);
  CHECK(s.initial_stress[0].stress[5] == 3);
  CHECK(s.initial_stress[0].bodies == std::vector<int>{1});
  CHECK(s.initial_stress[1].kind == fdem::InitialStressSpec::Kind::geostatic);
  CHECK(s.initial_stress[1].surface == 1.0);
  CHECK(s.initial_stress[1].k0 == 0.5);
}

TEST_CASE("initial_stress and absorbing: errors name the key", "[io][initial_stress]") {
  CHECK_THAT(
      error(scene_with("initial_stress:\n  - {uniform: [1, 2, 3]}\n")),
      Contains("scene.yaml:9:15:") && Contains("initial_stress[0].uniform: expected 6 numbers"));
  CHECK_THAT(
      error(scene_with("initial_stress:\n  - {geostatic: {surface: 1, k0: 0.5}}\n", "[0, 0, 0]")),
      Contains("initial_stress[0].geostatic: a geostatic stress is the weight of the ground "
               "above: it needs a non-zero top-level 'gravity'"));
  CHECK_THAT(error(scene_with("initial_stress:\n  - {geostatic: {surface: 1, k0: -0.5}}\n")),
             Contains("initial_stress[0].geostatic.k0: -0.5 is impossible"));
  CHECK_THAT(error(scene_with("initial_stress:\n  - {geostatic: {surface: 1}}\n")),
             Contains("initial_stress[0].geostatic.k0: missing required key 'k0'"));
  CHECK_THAT(error(scene_with("initial_stress:\n  - {bodies: [a]}\n")),
             Contains("initial_stress[0]: give one of 'uniform' or 'geostatic'"));
  CHECK_THAT(error(scene_with("initial_stress:\n  - {uniform: [0, 0, 0, 0, 0, 0]}\n"
                              "  - {uniform: [0, 0, 0, 0, 0, 0], bodies: [b]}\n")),
             Contains("initial_stress[1]: body 'b' already has an initial stress"));
  CHECK_THAT(error(scene_with("absorbing:\n  - {region: {box: {min: [0, 0, 0]}}}\n")),
             Contains("absorbing[0].region.box.max: missing required key 'max'"));
}

TEST_CASE("quasi_static: local damping and the time it ends, errors name the key",
          "[io][quasi_static]") {
  const fdem::Scene off = fdem::parse_scene(scene_with(""), "scene.yaml");
  CHECK_FALSE(off.quasi_static.active_at(0.0));
  const fdem::Scene s = fdem::parse_scene(
      scene_with("quasi_static: {local_damping: 0.8, until: 0.05}\n"), "scene.yaml");
  CHECK(s.quasi_static.local_damping == 0.8);
  CHECK(s.quasi_static.active_at(0.0499));
  CHECK_FALSE(s.quasi_static.active_at(0.05));
  const fdem::Scene whole =
      fdem::parse_scene(scene_with("quasi_static: {local_damping: 0.7}\n"), "scene.yaml");
  CHECK(whole.quasi_static.active_at(1e9));
  CHECK_THAT(
      error(scene_with("quasi_static: {local_damping: 1.0}\n")),
      Contains("scene.yaml:8:31:") && Contains("quasi_static.local_damping: must be in (0, 1)"));
  CHECK_THAT(error(scene_with("quasi_static: {until: 0.1}\n")),
             Contains("quasi_static.local_damping: missing required key 'local_damping'"));
  CHECK_THAT(error(scene_with("quasi_static: {local_damping: 0.8, until: -1}\n")),
             Contains("quasi_static.until"));
  CHECK_THAT(error(scene_with("quasi_static: {local_damping: 0.8, ratio: 1}\n")),
             Contains("quasi_static") && Contains("ratio"));
  // The equilibrium test: off by default, a fraction in (0, 1).
  CHECK(whole.quasi_static.equilibrium_ratio == 0.0);
  const fdem::Scene stop = fdem::parse_scene(
      scene_with("quasi_static: {local_damping: 0.8, equilibrium_ratio: 1e-5}\n"), "scene.yaml");
  CHECK(stop.quasi_static.equilibrium_ratio == 1e-5);
  for (const char* bad : {"0", "1", "-1e-5", "2"})
    CHECK_THAT(
        error(scene_with(std::string("quasi_static: {local_damping: 0.8, "
                                     "equilibrium_ratio: ") +
                         bad + "}\n")),
        Contains("scene.yaml:8:") && Contains("quasi_static.equilibrium_ratio: must be in (0, 1)"));
}

TEST_CASE(
    "quasi_static.damping: local (the default) or kinetic, with local damping beside it or not",
    "[io][quasi_static]") {
  const fdem::Scene local = fdem::parse_scene(
      scene_with("quasi_static: {damping: local, local_damping: 0.6}\n"), "scene.yaml");
  CHECK(local.quasi_static.damping == fdem::QuasiStaticDamping::local);
  CHECK(local.quasi_static.local_damping == 0.6);
  const fdem::Scene kinetic = fdem::parse_scene(
      scene_with("quasi_static: {damping: kinetic, until: 0.05, equilibrium_ratio: 1e-4}\n"),
      "scene.yaml");
  CHECK(kinetic.quasi_static.kinetic());
  CHECK(kinetic.quasi_static.local_damping == 0.0);
  CHECK(kinetic.quasi_static.active_at(0.0));
  CHECK_FALSE(kinetic.quasi_static.active_at(0.05));
  CHECK(kinetic.quasi_static.equilibrium_ratio == 1e-4);
  // Local damping besides, for the highest modes' vibration: 0 allowed here.
  const fdem::Scene both = fdem::parse_scene(
      scene_with("quasi_static: {damping: kinetic, local_damping: 0.1}\n"), "scene.yaml");
  CHECK(both.quasi_static.kinetic());
  CHECK(both.quasi_static.local_damping == 0.1);
  CHECK(fdem::parse_scene(scene_with("quasi_static: {damping: kinetic, local_damping: 0}\n"),
                          "scene.yaml")
            .quasi_static.local_damping == 0.0);
  CHECK_THAT(
      error(scene_with("quasi_static: {damping: kinetic, local_damping: 1}\n")),
      Contains("scene.yaml:8:") && Contains("quasi_static.local_damping: must be in [0, 1)"));
  CHECK_THAT(error(scene_with("quasi_static: {local_damping: 0}\n")),
             Contains("quasi_static.local_damping: must be in (0, 1)"));
  CHECK_THAT(error(scene_with("quasi_static: {damping: viscous}\n")),
             Contains("scene.yaml:8:") && Contains("quasi_static.damping") && Contains("local") &&
                 Contains("kinetic"));
  CHECK_THAT(error(scene_with("quasi_static: {damping: local}\n")),
             Contains("quasi_static.local_damping: missing required key 'local_damping'"));
}
