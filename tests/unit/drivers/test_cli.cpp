// The `fdem` command as a user runs it: exit codes, messages, and the files of an output directory
// (summary.json, energy.csv, bodies.csv, frames.pvd + .vtu read back with VTK).
#include <sys/wait.h>
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_support.hpp"
#include "json_test_support.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using fdem_test::critical_step_from_check;
using fdem_test::format_g;
using fdem_test::Json;
using fdem_test::Outcome;
using fdem_test::read_text;
using fdem_test::run_fdem;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

constexpr double kGravity = 9.81;  // m/s^2, as in the scenes below

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::stringstream ss(s);
  for (std::string p; std::getline(ss, p, sep);) parts.push_back(p);
  return parts;
}

// Rows of a CSV file (header first), each split at commas.
std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& line : split(read_text(path), '\n'))
    if (!line.empty()) rows.push_back(split(line, ','));
  return rows;
}

struct PvdEntry {
  double time;
  std::string file;
};

std::vector<PvdEntry> read_pvd(const std::string& path) {
  std::vector<PvdEntry> entries;
  const std::string text = read_text(path);
  const std::regex dataset(R"re(<DataSet\s+timestep="([^"]+)"[^>]*\sfile="([^"]+)")re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), dataset);
       it != std::sregex_iterator(); ++it)
    entries.push_back({std::stod((*it)[1]), (*it)[2]});
  return entries;
}

struct Frame {
  vtkIdType points = 0, cells = 0;
  std::vector<double> displacement, velocity, stress, coordinates;  // flattened tuples
  int displacement_components = 0, velocity_components = 0, stress_components = 0;
};

std::vector<double> flatten(vtkDataArray* a) {
  std::vector<double> out;
  if (!a) return out;
  for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t)
    for (int c = 0; c < a->GetNumberOfComponents(); ++c) out.push_back(a->GetComponent(t, c));
  return out;
}

Frame read_frame(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  Frame f;
  f.points = grid->GetNumberOfPoints();
  f.cells = grid->GetNumberOfCells();
  if (grid->GetPoints()) f.coordinates = flatten(grid->GetPoints()->GetData());
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement");
  vtkDataArray* v = grid->GetPointData()->GetArray("velocity");
  vtkDataArray* s = grid->GetCellData()->GetArray("stress");
  f.displacement_components = u ? u->GetNumberOfComponents() : 0;
  f.velocity_components = v ? v->GetNumberOfComponents() : 0;
  f.stress_components = s ? s->GetNumberOfComponents() : 0;
  f.displacement = flatten(u);
  f.velocity = flatten(v);
  f.stress = flatten(s);
  return f;
}

bool all_finite(const std::vector<double>& values) {
  for (double x : values)
    if (!std::isfinite(x)) return false;
  return true;
}

// A 1 m soft cube, 2×2×2 cells (27 nodes, 48 tets), centroid at z0 = 1.5 m, falling freely.
const char* falling_box = R"(name: falling-box
time: {end: 0.05}
gravity: [0, 0, -9.81]
materials:
  soft:
    density: 1000
    elastic: {young: 1.0e6, poisson: 0.25}
bodies:
  - name: box
    mesh: {box: {min: [0, 0, 1], max: [1, 1, 2], cells: [2, 2, 2]}}
    material: soft
output:
  every: 0.01
)";

// The same cube standing on its held bottom nodes: gravity deforms it, so a too-large step blows
// up.
const char* standing_column = R"(name: standing-column
time: {end: 0.5}
gravity: [0, 0, -9.81]
materials:
  soft:
    density: 1000
    elastic: {young: 1.0e6, poisson: 0.25}
bodies:
  - name: column
    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2]}}
    material: soft
loads:
  - {region: {box: {min: [-0.1, -0.1, -0.1], max: [1.1, 1.1, 0.1]}}, velocity: [0, 0, 0]}
output:
  every: 0.01
)";

}  // namespace

TEST_CASE("fdem --version prints the version and exits 0", "[cli]") {
  TempDir dir;
  const Outcome o = run_fdem(dir, "--version");
  CHECK(o.exit_code == 0);
  CHECK(std::regex_match(o.out, std::regex(R"(fdem [0-9]+\.[0-9]+\.[0-9]+\n)")));
  CHECK(o.err.empty());
}

TEST_CASE("fdem with a wrong command line exits 2 with the usage", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", falling_box);
  SECTION("no arguments") {
    const Outcome o = run_fdem(dir, "");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("usage:") && Contains("fdem run SCENE.yaml"));
  }
  SECTION("unknown command") {
    const Outcome o = run_fdem(dir, "frobnicate scene.yaml");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: unknown command 'frobnicate'"));
    CHECK_THAT(o.err, Contains("usage:"));
  }
  SECTION("unknown option") {
    const Outcome o = run_fdem(dir, "run scene.yaml --fast");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: unknown option '--fast'"));
    CHECK_THAT(o.err, Contains("usage:"));
    CHECK_FALSE(fs::exists(dir / "out"));  // nothing was run
  }
  SECTION("option without its value") {
    const Outcome o = run_fdem(dir, "run scene.yaml -o");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: -o needs a value"));
  }
  SECTION("run without a scene") {
    const Outcome o = run_fdem(dir, "run -q");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: run needs a scene file"));
  }
  SECTION("two scenes") {
    const Outcome o = run_fdem(dir, "check scene.yaml other.yaml");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("unexpected argument 'other.yaml'"));
  }
  SECTION("an output directory that cannot be created") {
    write_text(dir / "plain_file", "");
    const Outcome o = run_fdem(dir, "run scene.yaml -q -o plain_file/out");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: error: cannot create the output directory "
                                 "'plain_file/out' (-o): "));
  }
  SECTION("a scene file that does not exist") {
    const Outcome o = run_fdem(dir, "check missing.yaml");
    CHECK(o.exit_code == 2);
    CHECK(o.err ==
          "fdem: error: missing.yaml: cannot open the scene file (does it exist and is "
          "it readable?)\n");
  }
}

TEST_CASE("fdem check prints the scene contents and stages without stepping", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", falling_box);
  const Outcome o = run_fdem(dir, "check scene.yaml");
  CHECK(o.exit_code == 0);
  CHECK_THAT(o.out, StartsWith("scene 'falling-box' (scene.yaml)"));
  CHECK_THAT(o.out, Contains("soft             density 1000 kg/m^3, E 1e+06 Pa, nu 0.25, "
                             "neo-hookean"));
  CHECK_THAT(o.out, Contains("box              1 discrete element(s), material soft"));
  CHECK_THAT(o.out, Contains("mesh: 27 nodes, 48 tetrahedra, 1 discrete elements"));
  CHECK_THAT(o.out, Contains("stages:\n    internal forces (tetrahedra)\n"));
  CHECK_THAT(o.out, Contains("joint forces: skipped (no joints)"));
  CHECK_THAT(o.out, Contains("external forces: gravity (its weights start the internal forces' "
                             "sums)\n"));
  CHECK_THAT(o.out, Contains("integrate (central difference)"));
  // Automatic step = default safety 0.7 × the critical step.
  const double critical = critical_step_from_check(o.out);
  REQUIRE(critical > 0.0);
  std::smatch m;
  REQUIRE(std::regex_search(o.out, m, std::regex(R"(step ([0-9.eE+-]+) s \(auto)")));
  CHECK(std::stod(m[1]) == Approx(0.7 * critical).epsilon(1e-5));
  CHECK_FALSE(fs::exists(dir / "out"));

  SECTION("--set changes what check reports") {
    const Outcome s = run_fdem(dir, "check scene.yaml --set time.end=0.5 --set=time.safety=0.35");
    CHECK(s.exit_code == 0);
    CHECK_THAT(s.out, Contains("time: end 0.5 s"));
    REQUIRE(std::regex_search(s.out, m, std::regex(R"(step ([0-9.eE+-]+) s \(auto)")));
    CHECK(std::stod(m[1]) == Approx(0.35 * critical).epsilon(1e-5));
  }
  SECTION("a fixed step is reported as fixed") {
    const Outcome s = run_fdem(dir, "check scene.yaml --set time.step=1e-3");
    CHECK(s.exit_code == 0);
    CHECK_THAT(s.out, Contains("step 0.001 s (fixed; critical"));
    CHECK_THAT(s.out, Contains("50 steps"));
  }
}

TEST_CASE("fdem on a bad scene exits 2 with one located paragraph", "[cli]") {
  TempDir dir;
  std::string text = falling_box;
  text.replace(text.find("density: 1000"), 13, "density: -1000");  // line 6
  write_text(dir / "bad.yaml", text);
  write_text(dir / "scene.yaml", falling_box);
  SECTION("an impossible value, for check and for run") {
    for (const char* command : {"check", "run"}) {
      const Outcome o = run_fdem(dir, std::string(command) + " bad.yaml -o out");
      CHECK(o.exit_code == 2);
      CHECK(o.err ==
            "fdem: error: bad.yaml:6:14: materials.soft.density: -1000 is impossible: "
            "density (kg/m^3) must be > 0\n");
      CHECK_FALSE(fs::exists(dir / "out"));
    }
  }
  SECTION("a misspelt key") {
    std::string typo = falling_box;
    typo.replace(typo.find("gravity:"), 8, "gravty:");  // line 3
    write_text(dir / "typo.yaml", typo);
    const Outcome o = run_fdem(dir, "run typo.yaml");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: error: typo.yaml:3:1: gravty: unknown key 'gravty'. Did "
                                 "you mean 'gravity'?"));
    CHECK(std::count(o.err.begin(), o.err.end(), '\n') == 1);
  }
  SECTION("an error in a --set value") {
    const Outcome o = run_fdem(dir, "run scene.yaml --set time.end");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, Contains("expected key.path=value"));
  }
  SECTION("malformed YAML") {
    write_text(dir / "broken.yaml", "time: {end: 0.05\nmaterials:\n");
    const Outcome o = run_fdem(dir, "check broken.yaml");
    CHECK(o.exit_code == 2);
    CHECK_THAT(o.err, StartsWith("fdem: error: broken.yaml:2:"));
    CHECK_THAT(o.err, Contains("not valid YAML"));
  }
}

TEST_CASE("fdem run writes a complete output directory", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", falling_box);
  const Outcome o = run_fdem(dir, "run scene.yaml -o results");
  REQUIRE(o.exit_code == 0);
  // Progress line, stage table and the closing line go to stderr.
  CHECK_THAT(o.err, Contains("step 10/10"));
  CHECK_THAT(o.err, Contains("internal_forces"));
  CHECK_THAT(o.err, Contains("element-steps/s"));
  CHECK_THAT(o.err, Contains("results in results"));
  const std::string out = dir / "results";

  // summary.json: every key of the contract, with values that follow from the scene.
  const Json s = fdem_test::parse_json(read_text(out + "/summary.json"));
  CHECK(s["scene"].str() == "falling-box");
  CHECK(s["status"].str() == "completed");
  CHECK_FALSE(s.has("reason"));
  CHECK(s["ranks"].num() == 1);
  const double dt = s["time_step"].num();
  const double critical = s["critical_time_step"].num();
  CHECK(dt == Approx(0.7 * critical).epsilon(1e-12));
  const long steps = static_cast<long>(s["steps"].num());
  CHECK(steps == static_cast<long>(std::ceil(0.05 / dt - 1e-9)));
  CHECK(s["end_time"].num() == Approx(steps * dt).epsilon(1e-12));
  CHECK(s["end_time"].num() >= 0.05 - 1e-12);
  CHECK(s["wall_seconds"].num() > 0.0);
  CHECK(s["wall_seconds"].num() < 10.0);
  CHECK(s["nodes"].num() == 27);
  CHECK(s["elements"].num() == 48);
  CHECK(s["joints"].num() == 0);
  CHECK(s["broken_joints"].num() == 0);
  const Json& stages = s["stages"];
  REQUIRE(stages.type == Json::Type::object);
  CHECK(stages["internal_forces"]["calls"].num() == steps);
  CHECK(stages["integrate"]["calls"].num() == steps);
  // Gravity's weights start the internal forces: no external force stage runs for them.
  CHECK_FALSE(stages.has("external_forces"));
  CHECK(stages["internal_forces"]["seconds"].num() >= 0.0);
  CHECK_FALSE(stages.has("contact_forces"));  // stages that never ran are left out
  CHECK(s["throughput"]["element_steps_per_second"].num() ==
        Approx(48.0 * steps / s["wall_seconds"].num()).epsilon(1e-9));
  const Json& e = s["energy"];
  for (const char* key : {"kinetic", "strain", "gravity", "contact", "joint", "dissipated_fracture",
                          "dissipated_friction", "dissipated_damping", "dissipated_boundary",
                          "external_work", "balance_error"}) {
    INFO(key);
    CHECK(e[key].type == Json::Type::number);
  }
  // A free fall only trades gravity potential for kinetic energy (M = 1000 kg).  The kinetic term
  // is ½M·v(t−dt/2)·v(t+dt/2) = ½M g²(t² − dt²/4): the sum is the constant −M(g·dt)²/8 of step 0.
  CHECK(e["kinetic"].num() > 0.5 * 1000 * std::pow(kGravity * 0.04, 2));
  CHECK(e["kinetic"].num() + e["gravity"].num() ==
        Approx(-1000 * std::pow(kGravity * dt, 2) / 8).margin(1e-9 * e["kinetic"].num()));
  CHECK(std::abs(e["strain"].num()) < 1e-9 * e["kinetic"].num());
  CHECK(e["contact"].num() == 0);
  CHECK(e["external_work"].num() == 0);
  CHECK(e["balance_error"].num() < 1e-9);
  CHECK(std::regex_match(s["state_hash"].str(), std::regex("[0-9a-f]{16}")));

  // energy.csv: header, one row per output time, increasing times, tiny balance error; the last
  // row is the state summary.json reports.
  const auto energy = read_csv(out + "/energy.csv");
  REQUIRE(energy.size() >= 3);
  CHECK(energy[0] == std::vector<std::string>{"time", "kinetic", "strain", "gravity", "contact",
                                              "joint", "dissipated_fracture", "dissipated_friction",
                                              "dissipated_damping", "external_work", "total",
                                              "balance_error", "dissipated_boundary"});
  for (std::size_t r = 1; r < energy.size(); ++r) {
    INFO("energy.csv row " << r);
    REQUIRE(energy[r].size() == 13);
    if (r > 1) CHECK(std::stod(energy[r][0]) > std::stod(energy[r - 1][0]));
    CHECK(std::abs(std::stod(energy[r][11])) < 1e-9);
    double sum = -std::stod(energy[r][9]);  // stored energies and dissipation − external work
    for (int k = 1; k <= 8; ++k) sum += std::stod(energy[r][k]);
    sum += std::stod(energy[r][12]);  // dissipated_boundary, the column added last
    CHECK(std::stod(energy[r][10]) == Approx(sum).margin(1e-9 * (1 + std::stod(energy[r][1]))));
  }
  CHECK(std::stod(energy.back()[1]) == Approx(e["kinetic"].num()).epsilon(1e-10));
  CHECK(std::stod(energy.back()[3]) == Approx(e["gravity"].num()).epsilon(1e-10));

  // frames.pvd: one frame per output time (t = 0, every 0.01 s, and the end), each a readable .vtu.
  const auto frames = read_pvd(out + "/frames.pvd");
  REQUIRE(frames.size() == 6);
  CHECK(frames.front().time == 0.0);
  CHECK(frames.back().time == Approx(s["end_time"].num()).epsilon(1e-12));
  for (std::size_t i = 1; i < frames.size(); ++i) {
    CHECK(frames[i].time > frames[i - 1].time);
    CHECK(frames[i].time >= 0.01 * i - 1e-12);
    CHECK(frames[i].time < 0.01 * i + dt);
  }

  // bodies.csv: one row per piece per frame, at the frame times; mass, and rigid free fall.
  const auto bodies = read_csv(out + "/bodies.csv");
  REQUIRE(bodies.size() == frames.size() + 1);
  CHECK(bodies[0] == std::vector<std::string>{"time", "body", "piece", "mass", "x", "y", "z", "vx",
                                              "vy", "vz", "rx", "ry", "rz"});
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& row = bodies[i + 1];
    INFO("bodies.csv row " << i + 1);
    REQUIRE(row.size() == 13);
    const double t = std::stod(row[0]);
    CHECK(t == Approx(frames[i].time).epsilon(1e-10));
    CHECK(row[1] == "box");
    CHECK(row[2] == "0");
    CHECK(std::stod(row[3]) == Approx(1000.0).epsilon(1e-12));  // ρ·V = 1000 kg/m^3 × 1 m^3
    CHECK(std::stod(row[4]) == Approx(0.5).epsilon(1e-12));
    CHECK(std::stod(row[5]) == Approx(0.5).epsilon(1e-12));
    // The velocity is within one step's gain of g·t (whichever instant of the step it refers to).
    CHECK(std::abs(std::stod(row[9]) + kGravity * t) <= kGravity * dt * (1 + 1e-9));
    for (int k = 10; k < 13; ++k) CHECK(std::abs(std::stod(row[k])) < 1e-9);  // no rotation

    // The frame: 27 points, 48 tets, the arrays of the default fields; a rigid translation, so
    // every node's displacement and velocity are those of the centroid in bodies.csv.
    const std::string vtu = out + "/" + frames[i].file;
    REQUIRE(fs::exists(vtu));
    const Frame f = read_frame(vtu);
    CHECK(f.points == 27);
    CHECK(f.cells == 48);
    CHECK(f.displacement_components == 3);
    CHECK(f.velocity_components == 3);
    CHECK(f.stress_components == 9);
    REQUIRE(f.displacement.size() == 81);
    REQUIRE(f.velocity.size() == 81);
    CHECK(f.stress.size() == 9 * 48);
    const double dz = std::stod(row[6]) - 1.5;
    for (int n = 0; n < 27; ++n) {
      CHECK(f.displacement[3 * n + 2] == Approx(dz).margin(1e-9));
      CHECK(f.velocity[3 * n + 2] == Approx(std::stod(row[9])).margin(1e-9));
      CHECK(f.coordinates[3 * n + 2] - f.displacement[3 * n + 2] >= 1.0 - 1e-12);
    }
    double max_stress = 0.0;
    for (double x : f.stress) max_stress = std::max(max_stress, std::abs(x));
    CHECK(max_stress < 1e-3);  // Pa: a free fall does not strain the cube (E = 1 MPa)
  }

  SECTION("the same run twice gives the same state hash, a different run a different one") {
    const Outcome again = run_fdem(dir, "run scene.yaml -q -o again");
    REQUIRE(again.exit_code == 0);
    const Json s2 = fdem_test::parse_json(read_text(dir / "again/summary.json"));
    CHECK(s2["state_hash"].str() == s["state_hash"].str());
    CHECK(s2["energy"]["kinetic"].num() == s["energy"]["kinetic"].num());

    const Outcome other =
        run_fdem(dir, "run scene.yaml -q -o other --set bodies.0.velocity=[0,0,1]");
    REQUIRE(other.exit_code == 0);
    const Json s3 = fdem_test::parse_json(read_text(dir / "other/summary.json"));
    CHECK(s3["state_hash"].str() != s["state_hash"].str());
  }
  SECTION("-q silences progress and the stage table") {
    const Outcome quiet = run_fdem(dir, "run scene.yaml -q -o quiet");
    CHECK(quiet.exit_code == 0);
    CHECK(quiet.err.empty());
    CHECK(quiet.out.empty());
    CHECK(fs::exists(dir / "quiet/summary.json"));
  }
}

// Central difference with constant acceleration is exact at the step instants once the start-up
// is right (v at t = dt/2 is v0 + g·dt/2), so the centroid must follow z0 − g t²/2 to round-off.
TEST_CASE("a falling body's centroid in bodies.csv follows z0 - g t^2/2", "[cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", falling_box);
  REQUIRE(run_fdem(dir, "run scene.yaml -q -o out").exit_code == 0);
  const auto bodies = read_csv(dir / "out/bodies.csv");
  REQUIRE(bodies.size() == 7);
  for (std::size_t r = 1; r < bodies.size(); ++r) {
    const double t = std::stod(bodies[r][0]);
    const double z_exact = 1.5 - 0.5 * kGravity * t * t;
    INFO("t = " << t << " s, z = " << bodies[r][6] << " m, exact " << z_exact << " m");
    CHECK(std::stod(bodies[r][6]) == Approx(z_exact).epsilon(1e-6));
  }
}

TEST_CASE("an unstable run exits 3, says why, and leaves a valid last frame", "[cli]") {
  TempDir dir;
  write_text(dir / "column.yaml", standing_column);
  const Outcome check = run_fdem(dir, "check column.yaml");
  REQUIRE(check.exit_code == 0);
  const double critical = critical_step_from_check(check.out);
  REQUIRE(critical > 0.0);
  const std::string step = format_g(3.0 * critical);

  const Outcome o = run_fdem(dir, "run column.yaml -q -o out --set time.step=" + step);
  CHECK(o.exit_code == 3);
  CHECK_THAT(o.err, StartsWith("fdem: numerical failure at step "));
  CHECK_THAT(o.err, Contains("The time step is " + step + " s = 3 x the critical step"));
  CHECK_THAT(o.err, Contains("use time.step: auto or a step below"));
  CHECK_THAT(o.err, Contains("summary.json are in out"));
  CHECK(o.err.find("\n\n") == std::string::npos);  // one paragraph

  const Json s = fdem_test::parse_json(read_text(dir / "out/summary.json"));
  CHECK(s["status"].str() == "failed");
  CHECK_THAT(s["reason"].str(), StartsWith("numerical failure at step "));
  CHECK_THAT(s["reason"].str(), Contains("critical"));
  CHECK(s["time_step"].num() == Approx(3.0 * critical).epsilon(1e-5));
  CHECK(s["steps"].num() < 50);  // it stopped early (end/dt ≈ 76 steps)

  const auto frames = read_pvd(dir / "out/frames.pvd");
  REQUIRE_FALSE(frames.empty());
  const std::string last = dir / ("out/" + frames.back().file);
  REQUIRE(fs::exists(last));
  const Frame f = read_frame(last);
  CHECK(f.points == 27);
  CHECK(f.cells == 48);
  CHECK(f.displacement.size() == 81);
  CHECK(all_finite(f.coordinates));
  CHECK(all_finite(f.displacement));
  CHECK(all_finite(f.velocity));
  CHECK(all_finite(f.stress));
  // Every row that made it into the CSV files is finite too.
  for (const auto& file : {"/out/energy.csv", "/out/bodies.csv"})
    for (const auto& row : read_csv(dir.path().string() + file))
      for (const auto& cell : row) CHECK(cell.find("nan") == std::string::npos);
}
