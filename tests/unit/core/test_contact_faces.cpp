#include <catch2/catch.hpp>

#include "core/contact_faces.hpp"
#include "kuhn_boxes.hpp"

using namespace fdem;

namespace {

struct Counts {
  int surface = 0, folds = 0;
};

std::uint64_t bits_of(const Model& model, LocalIndex t) {
  const std::size_t at = 2 * static_cast<std::size_t>(t);
  return static_cast<std::uint32_t>(model.tets.contact_faces[at]) |
         static_cast<std::uint64_t>(static_cast<std::uint32_t>(model.tets.contact_faces[at + 1]))
             << 32;
}

Counts count_bits(const Model& model) {
  Counts c;
  for (LocalIndex t = 0; t < model.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::uint64_t bits = bits_of(model, t);
      if (!(bits & contact_face_bits::surface(f))) {
        for (int e = 0; e < 3; ++e) CHECK_FALSE(bits & contact_face_bits::fold(f, e));
        continue;
      }
      ++c.surface;
      for (int e = 0; e < 3; ++e) c.folds += (bits & contact_face_bits::fold(f, e)) ? 1 : 0;
    }
  return c;
}

}  // namespace

TEST_CASE("contact faces: a box's surface triangles, and folds only along its twelve edges",
          "[contact_faces]") {
  const int nx = 3, ny = 2, nz = 4;
  const Model model = test::kuhn_boxes_model({{Vec3(0.1, -0.2, 0.0), {nx, ny, nz}, 0.25}});
  REQUIRE(model.tets.contact_faces.size() == 2 * model.tets.gid.size());
  const Counts c = count_bits(model);
  // Two triangles per cell face on the box's six sides.
  CHECK(c.surface == 4 * (nx * ny + ny * nz + nx * nz));
  // Each cell edge along the box's twelve edges is a fold of the two triangles beside it.
  CHECK(c.folds == 2 * 4 * (nx + ny + nz));
  // Every fold edge lies on the box's edges: two of its coordinates at the box's bounds.
  const double lo[3] = {0.1, -0.2, 0.0}, hi[3] = {0.1 + nx * 0.25, -0.2 + ny * 0.25, nz * 0.25};
  for (LocalIndex t = 0; t < model.tets.size(); ++t)
    for (int f = 0; f < 4; ++f)
      for (int e = 0; e < 3; ++e) {
        if (!(bits_of(model, t) & contact_face_bits::fold(f, e))) continue;
        int w[3];
        face_corners(f, w);
        for (const int corner : {w[(e + 1) % 3], w[(e + 2) % 3]}) {
          const auto x = model.nodes.x0(model.tets.nodes[4 * t + corner]);
          int on_bounds = 0;
          for (int k = 0; k < 3; ++k)
            on_bounds += (std::abs(x[k] - lo[k]) < 1e-12 || std::abs(x[k] - hi[k]) < 1e-12);
          CHECK(on_bounds >= 2);
        }
      }
}

TEST_CASE("contact faces: each side of a box has one zone owner per vertex of its rim",
          "[contact_faces]") {
  const int nx = 2, ny = 3, nz = 1;
  const Model model = test::kuhn_boxes_model({{Vec3(0, 0, 0), {nx, ny, nz}, 0.3}});
  int owners = 0;
  for (LocalIndex t = 0; t < model.tets.size(); ++t)
    for (int f = 0; f < 4; ++f)
      for (int c = 0; c < 3; ++c) {
        const std::uint64_t bits = bits_of(model, t);
        if (!(bits & contact_face_bits::zone_owner(f, c))) continue;
        ++owners;
        CHECK(bits & contact_face_bits::fold_vertex(f, c));
        CHECK(bits & contact_face_bits::surface(f));
      }
  // A side of n1 × n2 cells has 2(n1 + n2) vertices on its rim, each owned once.
  CHECK(owners == 2 * (2 * (nx + ny) + 2 * (ny + nz) + 2 * (nx + nz)));
}

TEST_CASE("contact faces: two boxes that touch keep their own surfaces (groups never merge)",
          "[contact_faces]") {
  // The upper box sits on the lower one; their shared plane is on both surfaces.
  const Model model =
      test::kuhn_boxes_model({{Vec3(0, 0, 0), {2, 2, 1}, 0.5}, {Vec3(0, 0, 0.5), {2, 2, 1}, 0.5}});
  const Counts c = count_bits(model);
  CHECK(c.surface == 2 * 4 * (4 + 2 + 2));
  CHECK(c.folds == 2 * 2 * 4 * (2 + 2 + 1));
}

TEST_CASE("contact faces: the records give the same bits in any order, as directory ranks see them",
          "[contact_faces]") {
  Model model = test::kuhn_boxes_model({{Vec3(0, 0, 0), {2, 3, 2}, 0.2}});
  const std::vector<std::int32_t> expected = model.tets.contact_faces;
  std::vector<FaceRecord> faces = face_records(model, 0);
  std::reverse(faces.begin(), faces.end());
  keep_surface_faces(faces);
  std::vector<EdgeRecord> edges = edge_records(model, faces);
  std::rotate(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 3),
              edges.end());
  keep_fold_edges(edges);
  std::vector<VertexRecord> vertices = vertex_records(model, faces, edges);
  std::reverse(vertices.begin(), vertices.end());
  keep_fold_vertices(vertices);
  set_contact_faces(model, faces, edges, vertices);
  CHECK(model.tets.contact_faces == expected);
}

TEST_CASE("contact faces: build_model makes them under corner contact only where bodies can meet",
          "[contact_faces]") {
  // Corner contact set; one free box, a free box on a fixed one, and two fixed boxes.
  const auto build = [](const std::vector<bool>& fixed) {
    std::vector<BodyMesh> meshes;
    for (std::size_t b = 0; b < fixed.size(); ++b)
      meshes.push_back(test::kuhn_box({Vec3(0, 0, 0.5 * b), {1, 1, 1}, 0.5}));
    return build_model(test::kuhn_boxes_scene(fixed.size(), fixed), meshes);
  };
  CHECK(build({false}).tets.contact_faces.empty());
  CHECK(build({true, true}).tets.contact_faces.empty());
  const Model pair = build({true, false});
  CHECK(pair.tets.contact_faces.size() == 2 * static_cast<std::size_t>(pair.tets.size()));
  CHECK(count_bits(pair).surface == 2 * 6 * 2);  // two cubes: 6 sides of 2 triangles each
}
