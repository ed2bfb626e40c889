// Enclosed tets (TetJointState::enclosed): tets of a `joints: all` body with no corner on the
// body mesh's boundary are found by build_model and left out of contact while the body's joints
// hold.  Leaving them out changes no force (no left-out pair overlaps in a body deformed within
// its joints' reach) and a broken joint of the body brings them back.
#include <algorithm>
#include <catch2/catch.hpp>
#include <random>
#include <set>

#include "contact/contact_stage.hpp"
#include "core/model_builder.hpp"
#include "jointed_cube.hpp"

using namespace fdem;
using fdem::testing::jointed_scene;
using fdem::testing::kuhn_cube;
using fdem::testing::pairs_of;

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
        const double x = model.nodes.x0[3 * model.tets.nodes[4 * t + c] + d];
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
  // Narrowed by face planes only: the exact distance would drop the enclosed tets' pairs of
  // this scene too (test_tet_distance.cpp), leaving nothing for the skip to show.
  ContactStage skipping(model, ContactSettings{buffer, true, false});
  ContactStage all(model, ContactSettings{buffer, false, false});
  for (ContactStage* stage : {&skipping, &all}) {
    stage->set_bonds(model.tets.size(), testing::joint_bonds(model));
    stage->enclose(model.tets.enclosed);
    stage->detect(model);
  }
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
