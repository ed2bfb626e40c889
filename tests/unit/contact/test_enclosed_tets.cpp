// Enclosed tets (TetJointState::enclosed): tets of a `joints: all` body with no corner on the
// body mesh's boundary are found by build_model and left out of contact while the body's joints
// hold.  Leaving them out changes no force (no left-out pair overlaps in a body deformed within
// its joints' reach) and a broken joint of the body brings them back.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <memory>
#include <random>
#include <set>

#include "contact/contact_stage.hpp"
#include "core/model_builder.hpp"
#include "jointed_cube.hpp"

using namespace fdem;
using fdem::testing::jointed_scene;
using fdem::testing::kuhn_cube;
using fdem::testing::pairs_of;

namespace {

// Two stages of `model`, detected once: [0] leaves the enclosed tets out, [1] keeps them.  Pairs
// are narrowed by face planes only: the exact distance would drop the enclosed tets' pairs of the
// pressed cube too (test_tet_distance.cpp), leaving nothing for the skip to show.
std::array<std::unique_ptr<ContactStage>, 2> detected_stages(const Model& model, double buffer) {
  std::array<std::unique_ptr<ContactStage>, 2> stages = {
      std::make_unique<ContactStage>(model, ContactSettings{buffer, true, false}),
      std::make_unique<ContactStage>(model, ContactSettings{buffer, false, false})};
  for (const auto& stage : stages) {
    stage->set_bonds(model.tets.size(), testing::joint_bonds(model));
    stage->enclose(model.tets.enclosed);
    stage->detect(model);
  }
  return stages;
}

}  // namespace

TEST_CASE("build_model marks the jointed tets with no corner on the mesh boundary as enclosed",
          "[contact][enclosed]") {
  const int n = 4;
  const double h = 0.1;
  const Model model = build_model(jointed_scene(), {kuhn_cube(n, h)});
  REQUIRE(model.tets.enclosed.size() == static_cast<std::size_t>(model.tets.size()));
  long enclosed = 0;
  for (LocalIndex t = 0; t < model.tets.size(); ++t) {
    bool inside = true;  // by geometry: no corner on a face of the cube
    for (int c = 0; c < 4; ++c)
      for (int d = 0; d < 3; ++d) {
        const double x = model.nodes.x0(model.tets.nodes[4 * t + c])[d];
        inside = inside && x > 1e-9 && x < n * h - 1e-9;
      }
    CHECK(model.tets.enclosed[t] == (inside ? 1 : 0));
    enclosed += model.tets.enclosed[t];
  }
  // Every Kuhn tet holds its cell's corners 0 and 7: only the 2³ inner cells' 48 tets.
  CHECK(enclosed == 48);
}

TEST_CASE("enclosed tets stay out of contact, change no force, and return when a joint breaks",
          "[contact][enclosed]") {
  // The jointed cube and a plain block pressed 1 mm into its top face; the cube's nodes shaken
  // by 0.5 % of a cell, so its tets press into each other across the joints.
  Model model = testing::pressed_jointed_cube();
  const double buffer = 0.025;
  const auto stages = detected_stages(model, buffer);
  ContactStage& skipping = *stages[0];
  ContactStage& all = *stages[1];
  const long n_enclosed = std::count(model.tets.enclosed.begin(), model.tets.enclosed.end(), 1);
  REQUIRE(n_enclosed == 6 * 27);
  CHECK(skipping.left_out() == n_enclosed);
  CHECK(all.left_out() == 0);
  // The same candidates but those with an enclosed tet.
  std::set<std::pair<LocalIndex, LocalIndex>> expected;
  long with_enclosed = 0;
  for (const auto& [a, b] : pairs_of(all)) {
    if (model.tets.enclosed[a] || model.tets.enclosed[b])
      ++with_enclosed;
    else
      expected.emplace(a, b);
  }
  CHECK(with_enclosed > 0);
  CHECK(pairs_of(skipping) == expected);
  // Bit for bit the same forces: no left-out pair overlaps.
  std::vector<double> f_skipping(model.nodes.x.size(), 0.0), f_all(model.nodes.x.size(), 0.0);
  model.nodes.f.assign(model.nodes.x.size(), 0.0);
  const ContactForceSummary s_all = all.add_forces(model, 1e-6);
  f_all = model.nodes.f;
  model.nodes.f.assign(model.nodes.x.size(), 0.0);
  const ContactForceSummary s_skipping = skipping.add_forces(model, 1e-6);
  f_skipping = model.nodes.f;
  CHECK(s_all.active_pairs > 0);
  CHECK(s_all.active_pairs == s_skipping.active_pairs);
  CHECK(s_all.energy == s_skipping.energy);
  CHECK(f_skipping == f_all);
  // A broken joint anywhere in the body: its enclosed tets are candidates again.
  skipping.crack_body(0);
  CHECK(skipping.detection_due(model));
  skipping.detect(model);
  CHECK(skipping.left_out() == 0);
  CHECK(pairs_of(skipping) == pairs_of(all));
  // The joint state travels with the tets: enclosed, intact (the cube's other tets) or none.
  const std::vector<std::uint8_t> states = skipping.tet_joint_states();
  for (LocalIndex t = 0; t < model.tets.size(); ++t) {
    const TetJointState want = model.tets.enclosed[t] ? TetJointState::enclosed
                               : model.pieces.body_of(model.tets.piece[t]) == 0
                                   ? TetJointState::intact
                                   : TetJointState::none;
    CHECK(states[t] == static_cast<std::uint8_t>(want));
  }
}

TEST_CASE("positions at detection are kept for the nodes of tets that may pair only",
          "[contact][enclosed]") {
  Model model = testing::pressed_jointed_cube();
  const double buffer = 0.025;
  const auto stages = detected_stages(model, buffer);
  ContactStage& skipping = *stages[0];
  ContactStage& all = *stages[1];
  REQUIRE(skipping.left_out() > 0);
  // A node of enclosed tets only (the jointed cube's tets have their own nodes) and a node of a
  // tet that may pair.
  std::vector<int> in_enclosed(static_cast<std::size_t>(model.nodes.size()), 0),
      in_other(in_enclosed);
  for (LocalIndex t = 0; t < model.tets.size(); ++t)
    for (int c = 0; c < 4; ++c)
      ++(model.tets.enclosed[t] ? in_enclosed : in_other)[model.tets.nodes[4 * t + c]];
  LocalIndex inner = -1, outer = -1;
  for (LocalIndex i = 0; i < model.nodes.n_owned; ++i) {
    if (inner < 0 && in_enclosed[i] && !in_other[i]) inner = i;
    if (outer < 0 && in_other[i] && !in_enclosed[i]) outer = i;
  }
  REQUIRE(inner >= 0);
  REQUIRE(outer >= 0);
  const std::vector<double> at_detection = model.nodes.x;
  CHECK(skipping.positions_at_detection(model) == at_detection);
  CHECK(skipping.travel_since_detection(model) == 0.0);

  // The enclosed tets' node goes far: no detection is due where they are left out (their pairs
  // are not looked at until their body cracks), one is where they are not.
  Model moved = model;
  moved.nodes.x[3 * inner] += 10.0 * buffer;
  CHECK(skipping.travel_since_detection(moved) == 0.0);
  CHECK_FALSE(skipping.detection_due(moved));
  CHECK(all.travel_since_detection(moved) == Approx(10.0 * buffer).epsilon(1e-12));
  CHECK(all.detection_due(moved));
  // What checkpoints and migration carry: kept nodes as detected, the others where they are.
  std::vector<double> expected = at_detection;
  expected[3 * inner] = moved.nodes.x[3 * inner];
  CHECK(skipping.positions_at_detection(moved) == expected);
  CHECK(all.positions_at_detection(moved) == at_detection);

  // A node of a tet that may pair goes 0.3 buffer: its travel counts on both stages.
  moved.nodes.x[3 * outer + 1] -= 0.3 * buffer;
  CHECK(skipping.travel_since_detection(moved) == Approx(0.3 * buffer).epsilon(1e-12));
  CHECK_FALSE(skipping.detection_due(moved));
  moved.nodes.x[3 * outer + 1] -= 0.3 * buffer;
  CHECK(skipping.detection_due(moved));

  // The body cracks: the detection that follows looks at every tet, and keeps every node.
  skipping.crack_body(0);
  skipping.detect(moved);
  CHECK(skipping.left_out() == 0);
  CHECK(skipping.positions_at_detection(moved) == moved.nodes.x);
  Model further = moved;
  further.nodes.x[3 * inner + 2] += 0.6 * buffer;
  CHECK(skipping.detection_due(further));
}
