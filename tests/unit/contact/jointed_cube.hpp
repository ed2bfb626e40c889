// Test scenes of the contact tests: a cube meshed by Kuhn cells, and a rock scene with one
// jointed body (`joints: all`); a stage's pairs as a set.
#pragma once

#include <random>
#include <set>
#include <utility>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/model_builder.hpp"

namespace fdem::testing {

// A cube [0, n·h]³ of n³ cells of 6 Kuhn tets each (diagonal 0–7, positively oriented).
inline BodyMesh kuhn_cube(int n, double h) {
  BodyMesh mesh;
  mesh.source = "test";
  const auto id = [&](int i, int j, int k) {
    return static_cast<LocalIndex>(i + (n + 1) * (j + (n + 1) * k));
  };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) mesh.coords.insert(mesh.coords.end(), {i * h, j * h, k * h});
  const LocalIndex kuhn[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                 {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        LocalIndex corner[8];
        for (int c = 0; c < 8; ++c) corner[c] = id(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
        for (const auto& t : kuhn)
          for (int c = 0; c < 4; ++c) mesh.tets.push_back(corner[t[c]]);
      }
  return mesh;
}

inline Scene jointed_scene() {
  Scene scene;
  scene.source_path = "test";
  MaterialSpec rock;
  rock.name = "rock";
  rock.density = 2500;
  rock.elastic.young = 1e9;
  rock.elastic.poisson = 0.25;
  rock.contact.friction = 0.5;
  FractureSpec fracture;
  fracture.tensile_strength = 1e6;
  fracture.cohesion = 2e6;
  fracture.friction_angle_deg = 30.0;
  fracture.energy_I = 10.0;
  fracture.energy_II = 50.0;
  rock.fracture = fracture;
  scene.materials.push_back(rock);
  BodySpec body;
  body.name = "cube";
  body.material = 0;
  body.joints = JointPlacement::all;
  scene.bodies.push_back(body);
  return scene;
}

// A jointed 5³-cell cube of 0.1 m cells and a plain 0.3 m block ("lid", same rock) pressed 1 mm
// into its top; the cube's nodes shaken by up to 0.5 % of a cell (seed 7), so its tets press into
// each other across the joints.
inline Model pressed_jointed_cube() {
  Scene scene = jointed_scene();
  BodySpec lid = scene.bodies[0];
  lid.name = "lid";
  lid.joints = JointPlacement::none;
  scene.bodies.push_back(lid);
  BodyMesh block = kuhn_cube(1, 0.3);
  for (std::size_t i = 0; i < block.coords.size(); ++i) block.coords[i] += i % 3 == 2 ? 0.499 : 0.1;
  Model model = build_model(scene, {kuhn_cube(5, 0.1), block});
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> shake(-5e-4, 5e-4);
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces.body_of(model.nodes.piece[n]) == 0)
      for (int d = 0; d < 3; ++d) model.nodes.x[3 * n + d] += shake(random);
  return model;
}

// The tet pairs bonded by the model's joints.
inline std::vector<std::pair<LocalIndex, LocalIndex>> joint_bonds(const Model& model) {
  std::vector<std::pair<LocalIndex, LocalIndex>> out;
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    out.emplace_back(model.joints.tets[2 * j], model.joints.tets[2 * j + 1]);
  return out;
}

// The stage's candidate pairs (a, b) as a set.
inline std::set<std::pair<LocalIndex, LocalIndex>> pairs_of(const ContactStage& stage) {
  std::set<std::pair<LocalIndex, LocalIndex>> out;
  for (const CandidatePair& p : stage.candidates()) out.emplace(p.a, p.b);
  return out;
}

}  // namespace fdem::testing
