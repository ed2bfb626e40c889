// output.histories and load names: what the reader keeps, defaults, and each error message (file,
// line, key path, what is valid).
#include <catch2/catch.hpp>
#include <string>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;

namespace {

// Two bodies, a named region load, an unnamed body load and a tilt (of gravity, line 3);
// `output` is appended.
//  1 time: {end: 0.1}
//  ...
// 11 loads:
// 12   - {name: top, region: ..., velocity: [0, -1, null]}
// 13   - {bodies: [base], velocity: [0, 0, 0]}
// 14   - {tilt: ...}
// 15 output:
// 16   histories: ...
std::string scene_with(const std::string& output) {
  return "time: {end: 0.1}\n"
         "materials: {rock: {density: 2500, elastic: {young: 1.0e9, poisson: 0.25}}}\n"
         "gravity: [0, 0, -9.81]\n"
         "bodies:\n"
         "  - name: block\n"
         "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
         "    material: rock\n"
         "  - name: base\n"
         "    mesh: {box: {min: [0, 0, -1], max: [1, 1, 0]}}\n"
         "    material: rock\n"
         "loads:\n"
         "  - {name: top, region: {box: {min: [0, 0.9, 0], max: [1, 1, 1]}}, velocity: [0, -1, "
         "null]}\n"
         "  - {bodies: [base], velocity: [0, 0, 0]}\n"
         "  - {tilt: {axis: [0, 1, 0], rate: 1, max: 10}}\n"
         "output:\n" +
         output;
}

std::string input_error(const std::string& text) {
  try {
    fdem::parse_scene(text, "scene.yaml");
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("histories: loads by name (default: every load holding nodes), bodies, monitors",
          "[io][histories]") {
  const fdem::Scene all = fdem::parse_scene(scene_with("  histories: {}\n"), "scene.yaml");
  const fdem::HistoriesSpec& h = all.output.histories;
  CHECK(h.enabled);
  CHECK(h.every < 0);                        // the energy rows' interval
  CHECK(h.loads == std::vector<int>{0, 1});  // not the tilt
  CHECK(all.loads[0].name == "top");
  CHECK(all.loads[1].name == "load1");
  CHECK(h.bodies.empty());
  CHECK(h.monitors.empty());

  const fdem::Scene chosen =
      fdem::parse_scene(scene_with("  histories:\n"
                                   "    every: 0.001\n"
                                   "    loads: [load1]\n"
                                   "    bodies: all\n"
                                   "    monitors:\n"
                                   "      - {name: centre, point: [0.5, 0.5, 0.5]}\n"
                                   "      - {point: [0.1, 0.2, 0.3], stop_displacement: 0.02}\n"),
                        "scene.yaml");
  const fdem::HistoriesSpec& c = chosen.output.histories;
  CHECK(c.every == 0.001);
  CHECK(c.loads == std::vector<int>{1});
  CHECK(c.bodies == std::vector<int>{0, 1});
  REQUIRE(c.monitors.size() == 2);
  CHECK(c.monitors[0].name == "centre");
  CHECK(c.monitors[1].name == "monitor1");
  CHECK(c.monitors[1].point.isApprox(fdem::Vec3(0.1, 0.2, 0.3)));
  CHECK(c.monitors[0].stop_displacement == 0.0);  // never ends the run
  CHECK(c.monitors[1].stop_displacement == 0.02);
  // Where the point is written: a monitor outside every tet is reported there.
  CHECK(c.monitors[1].where == "scene.yaml:22:17: output.histories.monitors[1].point");

  const fdem::Scene none = fdem::parse_scene(scene_with("  every: 0.01\n"), "scene.yaml");
  CHECK_FALSE(none.output.histories.enabled);
}

TEST_CASE("histories: errors name the line, the key and what is valid", "[io][histories]") {
  CHECK_THAT(input_error(scene_with("  histories: {loads: [tpo]}\n")),
             Contains("scene.yaml:16:23: output.histories.loads[0]: no velocity or base-motion "
                      "load named 'tpo'. Did you mean 'top'? Valid velocity or base-motion load "
                      "names: top, load1."));
  CHECK_THAT(input_error(scene_with("  histories: {bodies: [blok]}\n")),
             Contains("output.histories.bodies[0]: no body named 'blok'. Did you mean 'block'?"));
  CHECK_THAT(input_error(scene_with("  histories: {bodies: [block, block]}\n")),
             Contains("body 'block' is listed twice"));
  CHECK_THAT(input_error(scene_with("  histories: {loads: top}\n")),
             Contains("output.histories.loads: expected 'all' or a list of velocity or "
                      "base-motion load names, e.g. [top]"));
  CHECK_THAT(input_error(scene_with("  histories: {evry: 1}\n")),
             Contains("unknown key 'evry'. Did you mean 'every'?"));
  CHECK_THAT(input_error(scene_with("  histories: {every: -1}\n")),
             Contains("output.histories.every: -1 is impossible"));
  CHECK_THAT(input_error(scene_with("  histories: {every: 1.0e-20}\n")),
             Contains("cannot advance time"));
  CHECK_THAT(input_error(scene_with("  histories: {loads: [], monitors: []}\n")),
             Contains("output.histories: nothing to record: list loads, bodies or monitors"));
  CHECK_THAT(input_error(scene_with("  histories: {monitors: [{name: a, point: [0, 0]}]}\n")),
             Contains("output.histories.monitors[0].point: expected three numbers"));
  CHECK_THAT(
      input_error(scene_with("  histories: {monitors: [{name: 'a,b', point: [0, 0, 0]}]}\n")),
      Contains("'a,b': a name in histories.csv column headers has no comma"));
  CHECK_THAT(input_error(scene_with("  histories: {monitors: [{name: a, point: [0, 0, 0]}, "
                                    "{name: a, point: [0, 0, 1]}]}\n")),
             Contains("monitor name 'a' is used twice"));
  CHECK_THAT(input_error(scene_with("  histories: {monitors: [{name: a}]}\n")),
             Contains("missing required key 'point'"));
  const auto stop_error = [](const std::string& value) {
    return input_error(
        scene_with("  histories: {monitors: [{name: a, point: [0, 0, 0], "
                   "stop_displacement: " +
                   value + "}]}\n"));
  };
  for (const char* bad : {"0", "-0.01"})
    CHECK_THAT(stop_error(bad), Contains("scene.yaml:16:73: output.histories.monitors[0]."
                                         "stop_displacement: must be a positive distance in m"));
  CHECK_THAT(stop_error(".inf"),
             Contains("monitors[0].stop_displacement: expected a finite number"));
}

TEST_CASE("load names: unique, column-safe, not on tilts", "[io][histories]") {
  std::string text = scene_with("  every: 0.01\n");
  const std::string top = "{name: top, region";
  std::string twice = text;
  twice.replace(twice.find("{bodies: [base]"), 1, "{name: top, ");
  CHECK_THAT(input_error(twice),
             Contains("scene.yaml:13:12: loads[1].name: load name 'top' is used twice"));
  std::string blank = text;
  blank.replace(blank.find(top), top.size(), "{name: 'my top', region");
  CHECK_THAT(input_error(blank), Contains("loads[0].name: 'my top': a name in histories.csv"));
  std::string tilt = text;
  tilt.replace(tilt.find("{tilt:"), 1, "{name: t, ");
  CHECK_THAT(input_error(tilt), Contains("give it alone"));
}
