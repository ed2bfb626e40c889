// Scene reader: the contact stage's keys (contact.*): values, defaults and their errors.
#include <catch2/catch.hpp>
#include <string>

#include "io/scene_reader.hpp"
#include "minimal_scene.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

using namespace fdem::test_scenes;

TEST_CASE("contact.dashpot: bodies or tets and nothing else", "[io]") {
  CHECK(fdem::parse_scene(minimal_plus("contact: {dashpot: bodies}\n"), "scene.yaml")
            .contact_body_dashpot);
  CHECK_FALSE(fdem::parse_scene(minimal_plus("contact: {dashpot: tets}\n"), "scene.yaml")
                  .contact_body_dashpot);
  const std::string msg = input_error(minimal_plus("contact: {dashpot: pieces}\n"));
  CHECK_THAT(msg, StartsWith("scene.yaml:10:"));
  CHECK_THAT(msg, Contains("contact.dashpot"));
  CHECK_THAT(msg, Contains("bodies"));
  CHECK_THAT(msg, Contains("tets"));
}

TEST_CASE("contact.sliver_tolerance: a fraction from 0 to 1e-6", "[io]") {
  CHECK(fdem::parse_scene(minimal_plus(""), "scene.yaml").contact_sliver_tolerance == 1e-6);
  CHECK(fdem::parse_scene(minimal_plus("contact: {sliver_tolerance: 0}\n"), "scene.yaml")
            .contact_sliver_tolerance == 0.0);
  CHECK(fdem::parse_scene(minimal_plus("contact: {sliver_tolerance: 1.0e-12}\n"), "scene.yaml")
            .contact_sliver_tolerance == 1e-12);
  for (const char* bad : {"-1e-9", "0.001", "small"}) {
    const std::string msg =
        input_error(minimal_plus(std::string("contact: {sliver_tolerance: ") + bad + "}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:"));
    CHECK_THAT(msg, Contains("contact.sliver_tolerance"));
  }
  CHECK_THAT(input_error(minimal_plus("contact: {sliver_tolerance: 0.001}\n")),
             Contains("between 0"));
}

TEST_CASE("contact.clip_replay: true by default, false clips every piece afresh", "[io]") {
  CHECK(fdem::parse_scene(minimal_plus(""), "scene.yaml").contact_clip_replay);
  CHECK(fdem::parse_scene(minimal_plus("contact: {clip_replay: true}\n"), "scene.yaml")
            .contact_clip_replay);
  CHECK_FALSE(fdem::parse_scene(minimal_plus("contact: {clip_replay: false}\n"), "scene.yaml")
                  .contact_clip_replay);
  const std::string msg = input_error(minimal_plus("contact: {clip_replay: sometimes}\n"));
  CHECK_THAT(msg, StartsWith("scene.yaml:10:"));
  CHECK_THAT(msg, Contains("contact.clip_replay"));
}

TEST_CASE(
    "contact.formulation: auto by default (corners in quasi-static runs without joints), "
    "potential or corners",
    "[io]") {
  using fdem::ContactFormulation;
  const auto scene = [](const std::string& extra) {
    return fdem::parse_scene(minimal_plus(extra), "scene.yaml");
  };
  const std::string quasi_static = "quasi_static: {local_damping: 0.8}\n";
  CHECK(scene("").contact_formulation == ContactFormulation::automatic);
  CHECK(scene("contact: {formulation: auto}\n").contact_formulation ==
        ContactFormulation::automatic);
  CHECK_FALSE(uses_corner_contact(scene("")));  // dynamic
  CHECK(uses_corner_contact(scene(quasi_static)));
  CHECK_FALSE(uses_corner_contact(scene("quasi_static: {local_damping: 0.8, until: 0.05}\n")));
  CHECK_FALSE(uses_corner_contact(scene(quasi_static + "contact: {formulation: potential}\n")));
  CHECK(uses_corner_contact(scene("contact: {formulation: corners}\n")));
  fdem::Scene jointed = scene(quasi_static);
  jointed.bodies[0].joints = fdem::JointPlacement::all;
  CHECK_FALSE(uses_corner_contact(jointed));
  fdem::Scene interface = scene(quasi_static);
  interface.interfaces.emplace_back();
  CHECK_FALSE(uses_corner_contact(interface));
  const std::string msg = input_error(minimal_plus("contact: {formulation: nodes}\n"));
  CHECK_THAT(msg, StartsWith("scene.yaml:10:"));
  CHECK_THAT(msg, Contains("contact.formulation"));
  CHECK_THAT(msg, Contains("auto"));
  CHECK_THAT(msg, Contains("potential"));
  CHECK_THAT(msg, Contains("corners"));
}
