// The contact stage's detection (contact/contact_stage_detection.cpp): pairs added when joints are
// released against a detection at the same positions.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "contact/contact_stage.hpp"
#include "contact/detection.hpp"
#include "jointed_cube.hpp"

using namespace fdem;
using fdem::testing::pairs_of;

TEST_CASE(
    "joints released one by one add the pairs a detection at the same positions would find, "
    "and many at once run that detection",
    "[contact][stage]") {
  // The shaken jointed cube and its lid; the stage under test detects once, then its bonds are
  // released in batches (1 to 3 joints, then 100) at moved positions; after each batch its list
  // must equal that of a stage given the same bonds and releases before its one detection, at the
  // positions of the first.
  const Model model = testing::pressed_jointed_cube();
  Model moved = model;
  for (double& x : moved.nodes.x) x += 2e-4;
  const double buffer = 0.025;
  const auto bonds = testing::joint_bonds(model);
  // The cube's body cracked, as the driver tells every rank before it releases a bond of it.
  const auto prepared = [&](ContactStage& stage) {
    stage.set_bonds(model.tets.size(), bonds);
    stage.enclose(model.tets.enclosed);
    stage.crack_body(0);
  };
  ContactStage stage(model, ContactSettings{buffer, true, true});
  prepared(stage);
  stage.detect(model);
  const long detections = stage.detections();
  std::vector<std::pair<LocalIndex, LocalIndex>> released;
  std::mt19937_64 random(5);
  std::vector<std::size_t> order(bonds.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), random);
  std::size_t next = 0;
  std::size_t before = stage.candidates().size();
  for (const std::size_t batch : {1, 2, 3, 1, 1, 2, 3, 3, 100}) {
    std::vector<std::pair<LocalIndex, LocalIndex>> now;
    for (std::size_t i = 0; i < batch; ++i) now.push_back(bonds[order[next++]]);
    released.insert(released.end(), now.begin(), now.end());
    stage.release_bonds(moved, now);
    ContactStage reference(model, ContactSettings{buffer, true, true});
    prepared(reference);
    reference.release_bonds(model, released);
    reference.detect(model);
    INFO("after " << released.size() << " joints released: " << stage.candidates().size()
                  << " pairs, detection " << reference.candidates().size());
    CHECK(pairs_of(stage) == pairs_of(reference));
    CHECK(stage.tet_joint_states() == reference.tet_joint_states());
    CHECK(stage.left_out() == reference.left_out());
  }
  CHECK(stage.candidates().size() > before);
  CHECK(stage.detections() == detections);
  CHECK_FALSE(stage.detection_due(moved));
}

TEST_CASE("a bond of a left-out tet released before its body cracked makes a detection due",
          "[contact][stage]") {
  // Its nodes' positions at the last detection were not kept (it was left out), so the pairs it
  // gains are found by a detection at the current positions.
  const Model model = testing::pressed_jointed_cube();
  const auto bonds = testing::joint_bonds(model);
  ContactStage stage(model, ContactSettings{0.025, true, true});
  stage.set_bonds(model.tets.size(), bonds);
  stage.enclose(model.tets.enclosed);
  stage.detect(model);
  REQUIRE(stage.left_out() > 0);
  CHECK_FALSE(stage.detection_due(model));
  std::size_t k = 0;
  while (k < bonds.size() && !model.tets.enclosed[bonds[k].first]) ++k;
  REQUIRE(k < bonds.size());
  stage.release_bonds(model, {bonds[k]});
  CHECK(stage.detection_due(model));
  stage.detect(model);
  CHECK_FALSE(stage.detection_due(model));
}

TEST_CASE(
    "the schedule's running bound of the travel since detection answers as the travel itself, "
    "step by step",
    "[contact][stage]") {
  // Random small steps of every node (one node faster), as the integration makes them; after each,
  // the stage's answer from its running bound must be the answer of the exact travel.
  Model model = testing::pressed_jointed_cube();
  const double buffer = 0.025;
  ContactStage stage(model, ContactSettings{buffer, true, true});
  stage.set_bonds(model.tets.size(), testing::joint_bonds(model));
  stage.enclose(model.tets.enclosed);
  stage.detect(model);
  std::mt19937_64 random(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int due = 0, quiet_steps = 0;
  for (int step = 0; step < 400; ++step) {
    double max_dx2 = 0.0, largest = 0.0;
    for (LocalIndex n = 0; n < model.nodes.n_owned; ++n) {
      const double speed = n == 7 ? 1.5e-4 : 2e-5;  // m per step
      double dx2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double dx = speed * (k == 0 ? 1.0 : unit(random));
        model.nodes.x[3 * n + k] += dx;
        largest = std::max(largest, std::abs(model.nodes.x[3 * n + k]));
        dx2 += dx * dx;
      }
      max_dx2 = std::max(max_dx2, dx2);
    }
    const double travel = stage.travel_since_detection(model);
    const bool answer = stage.detection_due_after_step(model, std::sqrt(max_dx2), largest);
    INFO("step " << step << ": travel since detection " << travel);
    REQUIRE(answer == detection_needed(travel, buffer));
    quiet_steps += !answer && travel < 0.4 * buffer;
    if (answer) {
      ++due;
      stage.detect(model);
    }
  }
  CHECK(due >= 2);  // the threshold was crossed, and crossed again after a detection
  CHECK(quiet_steps > 100);
}
