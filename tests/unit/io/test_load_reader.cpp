// Time histories and surface loads in the scene (io/load_reader): each form, the ramp's history,
// and each error message (file, line, key path, what is valid).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;

namespace {

// One body `block` and the given load lines (line 7 on).
std::string scene_with(const std::string& loads) {
  return "time: {end: 0.1}\n"
         "materials:\n"
         "  rock: {density: 2500, elastic: {young: 1.0e9, poisson: 0.25}}\n"
         "bodies:\n"
         "  - {name: block, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, material: rock}\n"
         "loads:\n" +
         loads;
}

std::string input_error(const std::string& text, const std::string& path = "scene.yaml") {
  try {
    fdem::parse_scene(text, path);
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

const char* top = "region: {box: {min: [-1, -1, 0.99], max: [2, 2, 2]}}";

}  // namespace

TEST_CASE("scene: velocity histories as a number, a table, a file and a smooth step",
          "[io][loads]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "fdem_load_reader").string();
  std::filesystem::create_directories(dir);
  {
    std::ofstream csv(dir + "/amp.csv");
    csv << "# amplitude\ntime,value\n0, 0\n0.01, 1\n\n0.05, 1\n0.06, 0\n";
  }
  const std::string text = scene_with(
      std::string("  - {") + top + ", velocity: [0, 0, -1], history: 0.5}\n" + "  - {" + top +
      ", velocity: [0, 0, -1], history: {table: [[0, 0], [0.01, 1], [0.02, 1]]}}\n" + "  - {" +
      top + ", velocity: [0, 0, -1], history: {file: amp.csv}}\n" + "  - {" + top +
      ", velocity: [0, 0, -1], history: {smooth_step: {start: 0.01, end: 0.03, shape: cubic}}}\n" +
      "  - {ramp: {direction: [1, 0, 0], history: {smooth_step: {end: 0.02, to: 3}}}}\n" +
      "  - {ramp: {direction: [1, 0, 0], rate: 2, max: 1, start: 0.01}}\n");
  const fdem::Scene s = fdem::parse_scene(text, dir + "/scene.yaml");
  REQUIRE(s.loads.size() == 6);
  using Kind = fdem::TimeHistory::Kind;
  CHECK(s.loads[0].history.kind == Kind::constant);
  CHECK(s.loads[0].history(1.0) == 0.5);
  CHECK(s.loads[1].history.kind == Kind::table);
  CHECK(s.loads[1].history(0.005) == Approx(0.5));
  CHECK(s.loads[2].history.times == std::vector<double>{0, 0.01, 0.05, 0.06});
  CHECK(s.loads[2].history(0.055) == Approx(0.5));
  CHECK(s.loads[3].history.shape == fdem::TimeHistory::Shape::cubic);
  CHECK(s.loads[3].history(0.02) == Approx(0.5));
  REQUIRE(s.loads[4].ramp.history);
  CHECK((*s.loads[4].ramp.history)(0.01) == Approx(1.5));
  CHECK_FALSE(s.loads[5].ramp.history);  // the rate/max/start keys as before
  CHECK(s.loads[5].ramp.rate == 2);
  std::filesystem::remove_all(dir);
}

TEST_CASE("scene: time history errors name the key, the line and what is valid", "[io][loads]") {
  const auto load = [](const std::string& history) {
    return input_error(scene_with(std::string("  - {") + top +
                                  ", velocity: [0, 0, -1], history: " + history + "}\n"));
  };
  CHECK_THAT(load("{table: [[0, 0]]}"), Contains("scene.yaml:7:") &&
                                            Contains("loads[0].history.table") &&
                                            Contains("at least two [time, value] pairs"));
  CHECK_THAT(load("{table: [[0, 0], [0, 1]]}"),
             Contains("loads[0].history.table[1][0]") && Contains("does not increase"));
  CHECK_THAT(load("{table: [[0, 0], [1, 2, 3]]}"),
             Contains("loads[0].history.table[1]") && Contains("a pair [time, value]"));
  CHECK_THAT(load("{table: [[-1, 0], [1, 2]]}"), Contains("must be >= 0"));
  CHECK_THAT(load("{smooth_step: {start: 1, end: 0.5}}"),
             Contains("loads[0].history.smooth_step.end") && Contains("must be after start"));
  CHECK_THAT(load("{smooth_step: {end: 1, shape: quartic}}"),
             Contains("smooth_step.shape") && Contains("cubic, quintic, sine"));
  CHECK_THAT(load("{smooth_stp: {end: 1}}"),
             Contains("loads[0].history.smooth_stp") && Contains("Did you mean 'smooth_step'?"));
  CHECK_THAT(load("{table: [[0, 0], [1, 1]], file: a.csv}"),
             Contains("loads[0].history") && Contains("expected one of: a number"));
  CHECK_THAT(load("{file: no-such.csv}"),
             Contains("loads[0].history.file") && Contains("no-such.csv' does not exist"));
  CHECK_THAT(input_error(scene_with("  - {bodies: [block], base_motion: {file: x.csv, direction: "
                                    "[1, 0, 0]}, history: 2}\n")),
             Contains("without 'region', 'velocity' or 'history'"));
  CHECK_THAT(
      input_error(scene_with(
          "  - {ramp: {direction: [1, 0, 0], rate: 1, history: {smooth_step: {end: 1}}}}\n")),
      Contains("loads[0].ramp.rate") && Contains("either 'history'"));
  CHECK_THAT(input_error(scene_with("  - {ramp: {direction: [1, 0, 0], rate: 1}}\n")),
             Contains("loads[0].ramp.max") && Contains("missing required key 'max'"));
}

TEST_CASE("scene: history files name the file and the line of a bad row", "[io][loads]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "fdem_load_reader_e").string();
  std::filesystem::create_directories(dir);
  const auto with_file = [&](const std::string& rows) {
    std::ofstream(dir + "/amp.csv") << rows;
    return input_error(scene_with(std::string("  - {") + top +
                                  ", velocity: [0, 0, -1], history: {file: amp.csv}}\n"),
                       dir + "/scene.yaml");
  };
  CHECK_THAT(with_file("time,value\n0, 0\n0.1; 2\n"),
             Contains("amp.csv:3:") && Contains("expected a row 'time, value'"));
  CHECK_THAT(with_file("0, 0\n0.1, 1\n0.1, 2\n"),
             Contains("amp.csv:3:") && Contains("does not increase"));
  CHECK_THAT(with_file("-0.1, 0\n0.1, 1\n"), Contains("amp.csv:1:") && Contains("negative"));
  CHECK_THAT(with_file("0, 0\n"), Contains("amp.csv") && Contains("at least two rows"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("scene: pressure and traction loads, and their errors", "[io][loads]") {
  const fdem::Scene s = fdem::parse_scene(
      scene_with(std::string("  - {name: confine, bodies: [block], pressure: 2.0e6}\n") + "  - {" +
                 top +
                 ", pressure: 1.0e5, follower: false, history: {smooth_step: {end: 0.01}}}\n" +
                 "  - {" + top + ", traction: [0, 1.0e3, 0]}\n"),
      "scene.yaml");
  REQUIRE(s.loads.size() == 3);
  using fdem::LoadSpec;
  using fdem::SurfaceLoadSpec;
  CHECK(s.loads[0].kind == LoadSpec::Kind::surface);
  CHECK(s.loads[0].surface.kind == SurfaceLoadSpec::Kind::pressure);
  CHECK(s.loads[0].surface.pressure == 2.0e6);
  CHECK(s.loads[0].surface.follower);
  CHECK(s.loads[0].bodies == std::vector<int>{0});
  CHECK_FALSE(s.loads[1].surface.follower);
  CHECK(s.loads[1].history(0.005) == Approx(0.5));
  CHECK(s.loads[2].surface.kind == SurfaceLoadSpec::Kind::traction);
  CHECK(s.loads[2].surface.traction.y() == 1.0e3);
  CHECK_THAT(input_error(scene_with("  - {bodies: [block], pressure: 1, traction: [0, 0, 1]}\n")),
             Contains("loads[0]") && Contains("either 'pressure'"));
  CHECK_THAT(input_error(scene_with("  - {bodies: [block], pressure: 1, velocity: [0, 0, 0]}\n")),
             Contains("loads[0].velocity") && Contains("prescribes no velocity"));
  CHECK_THAT(
      input_error(scene_with("  - {bodies: [block], traction: [0, 0, 1], follower: true}\n")),
      Contains("loads[0].follower") && Contains("applies to a pressure"));
  CHECK_THAT(
      input_error(scene_with("  - {bodies: [block], velocity: [0, 0, 0], follower: true}\n")),
      Contains("loads[0].follower") && Contains("pressure load only"));
  CHECK_THAT(input_error(scene_with("  - {pressure: 1}\n")),
             Contains("loads[0]") && Contains("needs 'bodies' or 'region'"));
  CHECK_THAT(input_error(scene_with("  - {bodies: [block], presure: 1}\n")),
             Contains("Did you mean 'pressure'?"));
  CHECK_THAT(input_error(scene_with("  - {bodies: [block], pressure: abc}\n")),
             Contains("loads[0].pressure") && Contains("expected a number"));
}
