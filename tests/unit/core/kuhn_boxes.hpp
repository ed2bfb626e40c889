// Boxes meshed in code (6 Kuhn tets per cubic cell, every tet positively oriented), each its own
// body of one piece, built into a model by build_model: for tests of core and contact that need
// a real mesh's connectivity without the drivers' generators.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "core/contact_faces.hpp"
#include "core/model_builder.hpp"
#include "core/scene.hpp"

namespace fdem::test {

struct BoxSpec {
  Vec3 lo;
  int cells[3];
  double cell;  // m
};

inline BodyMesh kuhn_box(const BoxSpec& box) {
  BodyMesh mesh;
  mesh.source = "kuhn box";
  const int n[3] = {box.cells[0] + 1, box.cells[1] + 1, box.cells[2] + 1};
  const auto node = [&](int i, int j, int k) {
    return static_cast<LocalIndex>(i + n[0] * (j + n[1] * k));
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        mesh.coords.push_back(box.lo.x() + i * box.cell);
        mesh.coords.push_back(box.lo.y() + j * box.cell);
        mesh.coords.push_back(box.lo.z() + k * box.cell);
      }
  const int axes[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < box.cells[2]; ++k)
    for (int j = 0; j < box.cells[1]; ++j)
      for (int i = 0; i < box.cells[0]; ++i)
        for (const auto& order : axes) {
          int at[3] = {i, j, k};
          LocalIndex tet[4];
          tet[0] = node(at[0], at[1], at[2]);
          for (int step = 0; step < 3; ++step) {
            ++at[order[step]];
            tet[step + 1] = node(at[0], at[1], at[2]);
          }
          const auto x = [&](LocalIndex v) {
            return Vec3(mesh.coords[3 * v], mesh.coords[3 * v + 1], mesh.coords[3 * v + 2]);
          };
          if ((x(tet[1]) - x(tet[0])).cross(x(tet[2]) - x(tet[0])).dot(x(tet[3]) - x(tet[0])) < 0)
            std::swap(tet[2], tet[3]);
          mesh.tets.insert(mesh.tets.end(), tet, tet + 4);
        }
  return mesh;
}

// A scene of one stone material (E = 1 GPa, ν 0.2, 2000 kg/m³, penalty 10 GPa) and `n_boxes`
// bodies "box0", "box1", ... (fixed where `fixed` says), with corner contact on.
inline Scene kuhn_boxes_scene(std::size_t n_boxes, const std::vector<bool>& fixed = {}) {
  Scene scene;
  scene.source_path = "test.yaml";
  scene.contact_formulation = ContactFormulation::corners;
  MaterialSpec stone;
  stone.name = "stone";
  stone.density = 2000;
  stone.elastic.young = 1e9;
  stone.elastic.poisson = 0.2;
  scene.materials.push_back(stone);
  for (std::size_t b = 0; b < n_boxes; ++b) {
    BodySpec body;
    body.name = "box" + std::to_string(b);
    body.material = 0;
    body.fixed = b < fixed.size() && fixed[b];
    scene.bodies.push_back(body);
  }
  return scene;
}

// kuhn_boxes_scene's model of the given boxes, free, with their contact faces.
inline Model kuhn_boxes_model(const std::vector<BoxSpec>& boxes) {
  std::vector<BodyMesh> meshes;
  for (const BoxSpec& box : boxes) meshes.push_back(kuhn_box(box));
  Model model = build_model(kuhn_boxes_scene(boxes.size()), meshes);
  // One box cannot meet another, and build_model leaves its contact faces out: made here, for the
  // tests of the faces themselves.
  if (model.tets.contact_faces.empty()) compute_contact_faces(model);
  return model;
}

}  // namespace fdem::test
