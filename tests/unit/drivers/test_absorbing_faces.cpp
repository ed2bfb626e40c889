// Which faces absorb: the mesh's boundary faces in the region box (not faces two tets share, nor
// faces bonded by joints), of the listed bodies; an entry that selects none is an input error
// from `fdem check` and `fdem run` alike.
#include <catch2/catch.hpp>
#include <string>

#include "cli_test_support.hpp"
#include "core/absorbing_boundary.hpp"
#include "core/error.hpp"
#include "drivers/scene_builders.hpp"
#include "io/scene_reader.hpp"

using Catch::Matchers::Contains;
using namespace fdem;

namespace {

// Two 2×2×2-cell boxes side by side along x (touching at x = 1); `rock` may be jointed.
std::string boxes(const std::string& absorbing, const std::string& joints = "none") {
  return "time: {end: 1.0e-4}\n"
         "materials:\n"
         "  rock:\n"
         "    density: 2000\n"
         "    elastic: {young: 1.0e8, poisson: 0.25}\n"
         "    fracture: {tensile_strength: 1e5, cohesion: 2e5, friction_angle: 30, energy_I: 10, "
         "energy_II: 50}\n"
         "bodies:\n"
         "  - {name: a, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2]}}, material: "
         "rock, joints: " +
         joints +
         "}\n"
         "  - {name: b, mesh: {box: {min: [1, 0, 0], max: [2, 1, 1], cells: [2, 2, 2]}}, material: "
         "rock}\n"
         "absorbing:\n" +
         absorbing;
}

std::vector<std::int64_t> faces_of(const std::string& text) {
  const Scene scene = parse_scene(text, "boxes.yaml");
  auto sim = builders::quiet_simulation(scene);
  return AbsorbingBoundary(scene.absorbing, sim->model()).counted_faces(sim->model());
}

}  // namespace

TEST_CASE("absorbing faces: boundary triangles in the box, per body, jointed or not",
          "[absorbing]") {
  // The base z = 0 of both boxes: 2 × 4 cells × 2 triangles.
  const std::string base = "  - {region: {box: {min: [-1, -1, -0.01], max: [3, 2, 0.01]}}}\n";
  CHECK(faces_of(boxes(base)) == std::vector<std::int64_t>{16});
  // Joints on every interior face of `a`: its interior faces are bonded, not boundary.
  CHECK(faces_of(boxes(base, "all")) == std::vector<std::int64_t>{16});
  // The plane x = 1 where the boxes touch: boundary faces of each mesh (8 + 8), a body filter.
  const std::string touching =
      "  - {region: {box: {min: [0.99, -1, -1], max: [1.01, 2, 2]}}, "
      "bodies: [b]}\n";
  CHECK(faces_of(boxes(touching)) == std::vector<std::int64_t>{8});
  // Two entries: a face goes to the first that selects it; the second gets the lower layer of
  // the four sides of each box (x = 1 counts for both meshes): 2 × 4 sides × 2 cells × 2.
  CHECK(faces_of(boxes(base + "  - {region: {box: {min: [-1, -1, -1], max: [3, 2, 0.6]}}}\n")) ==
        std::vector<std::int64_t>{16, 32});
  // The inside of a box has no boundary face.
  const std::string inside = "  - {region: {box: {min: [0.2, 0.2, 0.2], max: [0.8, 0.8, 0.8]}}}\n";
  std::string message;
  try {
    faces_of(boxes(inside));
  } catch (const InputError& e) {
    message = e.what();
  }
  CHECK_THAT(message, Contains("boxes.yaml: absorbing[0].region: no boundary face of the mesh"));
}

TEST_CASE("absorbing: keys checked, check and run refuse an empty selection alike",
          "[absorbing][cli]") {
  const auto error = [](const std::string& text) {
    try {
      parse_scene(text, "boxes.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(error(boxes("  - {region: {box: {min: [0, 0, 0], max: [1, 1, -1]}}}\n")),
             Contains("absorbing[0].region.box.max: each component of max must be at least min's"));
  CHECK_THAT(error(boxes("  - {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n")),
             Contains("absorbing[0].box: unknown key 'box'"));
  CHECK_THAT(error(boxes("  - {region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}, bodies: [c]}\n")),
             Contains("absorbing[0].bodies: no body named 'c'"));
  CHECK_THAT(error(boxes("  {region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}}\n")),
             Contains("absorbing: expected a list of absorbing boundaries"));
  fdem_test::TempDir dir;
  fdem_test::write_text(
      dir / "boxes.yaml",
      boxes("  - {region: {box: {min: [0.2, 0.2, 0.2], max: [0.8, 0.8, 0.8]}}}\n"));
  const fdem_test::Outcome check = fdem_test::run_fdem(dir, "check boxes.yaml");
  const fdem_test::Outcome run = fdem_test::run_fdem(dir, "run boxes.yaml -q -o out");
  CHECK(check.exit_code == 2);
  CHECK(run.exit_code == 2);
  CHECK_THAT(check.err, Contains("absorbing[0].region: no boundary face"));
  CHECK_THAT(run.err, Contains("absorbing[0].region: no boundary face"));
  fdem_test::write_text(dir / "ok.yaml",
                        boxes("  - {region: {box: {min: [-1, -1, -0.01], max: [3, 2, 0.01]}}}\n"));
  const fdem_test::Outcome ok = fdem_test::run_fdem(dir, "check ok.yaml");
  CHECK(ok.exit_code == 0);
  CHECK_THAT(ok.out, Contains("absorbing boundaries"));
}
