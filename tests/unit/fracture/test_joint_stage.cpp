// The joint stage's state as it travels between ranks: each joint's history as an opaque record,
// back bit for bit.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <utility>
#include <vector>

#include "../core/one_body_scene.hpp"
#include "core/model_builder.hpp"
#include "fracture/joint_stage.hpp"

using namespace fdem;

TEST_CASE("joint histories travel as opaque records and come back bit for bit",
          "[fracture][state]") {
  std::vector<JointHistory> history(4);
  history[1].broken = true;
  history[1].mode = FailureMode::shear;
  history[1].failure_time = 0.125;
  history[2].point[0].damage = 0.3;
  history[3].point[2].damage = 1.0 / 3.0;
  const std::vector<std::uint8_t> records = joint_records(history);
  CHECK(records.size() == 4 * sizeof(JointHistory));
  const std::vector<JointHistory> back = joint_histories(records);
  REQUIRE(back.size() == 4);
  CHECK(std::memcmp(back.data(), history.data(), records.size()) == 0);
  CHECK(back[1].broken);
  CHECK(back[1].mode == FailureMode::shear);
  CHECK(back[1].failure_time == 0.125);
  CHECK(back[3].point[2].damage == 1.0 / 3.0);
  CHECK(joint_histories({}).empty());
  CHECK_THROWS(joint_histories(std::vector<std::uint8_t>(sizeof(JointHistory) + 1)));
}

namespace {

// A jointed column of two Kuhn cells (12 tets, z from 0 to 2 m, joints on every inner face).
Model jointed_column() {
  Scene scene = test::one_rock_body("column");
  MaterialSpec& rock = scene.materials[0];
  rock.elastic.young = 1e9;
  FractureSpec f;
  f.tensile_strength = 1e6;
  f.cohesion = 2e6;
  f.friction_angle_deg = 30.0;
  f.energy_I = 40.0;  // J/m²: above what the penalty stores before the peak (10 J/m² at h = 1 m)
  f.energy_II = 200.0;  // J/m²: above the snap-back limit of 1 m joints (63 J/m²)
  rock.fracture = f;
  scene.bodies[0].joints = JointPlacement::all;
  BodyMesh mesh;
  mesh.source = "test";
  for (int k = 0; k < 3; ++k)  // node (i, j, k) = i + 2 j + 4 k
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        mesh.coords.insert(mesh.coords.end(), {1.0 * i, 1.0 * j, 1.0 * k});
  const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                          {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  for (int level = 0; level < 2; ++level)
    for (const auto& t : kuhn)
      for (int c = 0; c < 4; ++c) {
        const int b = t[c];  // cell corner: bits x, y, z
        mesh.tets.push_back((b & 1) + 2 * ((b >> 1) & 1) + 4 * (level + (b >> 2)));
      }
  return build_model(scene, {mesh});
}

// Whether tet t lies in the upper cell (centroid above z = 1).
// The pull below moves the upper cell's nodes by `lift` (m) a step; the stage reads the step
// back from x − step·v, so they get the matching velocity.
constexpr double kStep = 1e-3, kLift = 2.5e-6;

bool upper(const Model& m, LocalIndex t);

void set_lift_velocity(Model& m) {
  for (LocalIndex t = 0; t < m.tets.size(); ++t)
    if (upper(m, t))
      for (int c = 0; c < 4; ++c)
        m.nodes.v[3 * static_cast<std::size_t>(m.tets.nodes[4 * t + c]) + 2] = kLift / kStep;
}

bool upper(const Model& m, LocalIndex t) {
  double z = 0.0;
  for (int c = 0; c < 4; ++c) z += m.nodes.x0(static_cast<std::size_t>(m.tets.nodes[4 * t + c]))[2];
  return z > 4.0;
}

}  // namespace

TEST_CASE(
    "joint stage: the joints across a pulled gap break, the rest hold, a rebound copy goes on "
    "bit for bit",
    "[fracture][stage]") {
  Model model = jointed_column();
  REQUIRE(model.joints.size() > 0);
  JointStage stage(model);
  set_lift_velocity(model);
  JointStepSummary s = stage.add_forces(model, 0.0, kStep);
  CHECK(s.newly_broken == 0);
  CHECK(s.stored_energy == 0.0);

  // The upper cell lifted in 400 steps of 2.5 µm (to 1 mm), far past the separation at which these
  // joints break: every joint between the cells breaks, in mode I, dissipating G_I over the 1 m²
  // section between the cells; the joints inside each cell (moved rigidly) hold.
  double dissipated = 0.0;
  LocalIndex newly = 0;
  for (int step = 1; step <= 400; ++step) {
    for (LocalIndex t = 0; t < model.tets.size(); ++t)
      if (upper(model, t))
        for (int c = 0; c < 4; ++c)
          model.nodes.x[3 * static_cast<std::size_t>(model.tets.nodes[4 * t + c]) + 2] += kLift;
    std::fill(model.nodes.f.begin(), model.nodes.f.end(), 0.0);
    s = stage.add_forces(model, 0.001 * step, kStep);
    dissipated += s.fracture_dissipated;
    newly += s.newly_broken;
    CHECK(static_cast<LocalIndex>(stage.newly_broken().size()) == s.newly_broken);
  }
  long across = 0;
  for (LocalIndex j = 0; j < model.joints.size(); ++j) {
    const bool spans =
        upper(model, model.joints.tets[2 * j]) != upper(model, model.joints.tets[2 * j + 1]);
    across += spans;
    CHECK(static_cast<bool>(model.joints.broken[j]) == spans);
    if (spans) CHECK((stage.failure_time(j) > 0.0 && stage.failure_time(j) <= 0.4));
    if (spans) CHECK(stage.damage(j) == 1.0);
  }
  REQUIRE(across > 0);
  CHECK(newly == across);
  CHECK(s.broken == across);
  // G_I = 40 J/m² over 1 m²: 39.9974 J measured (2.5 µm steps; 25 µm steps give 37.97 J)
  CHECK(dissipated == Approx(40.0).epsilon(1e-3));

  // A second stage takes the history over (as after a migration) and marks one more joint
  // broken (as when another rank reports it): both go on with the same forces, bit for bit.
  Model copy = model;
  JointStage rebound(copy);
  rebound.rebind(copy, joint_histories(joint_records(stage.history())));
  LocalIndex intact = -1;
  for (LocalIndex j = 0; j < model.joints.size() && intact < 0; ++j)
    if (!model.joints.broken[j]) intact = j;
  REQUIRE(intact >= 0);
  for (auto [m, st] : {std::pair<Model*, JointStage*>{&model, &stage}, {&copy, &rebound}}) {
    st->mark_broken(*m, intact, 0.75, 1);
    CHECK(m->joints.broken[intact] == 1);
    CHECK(st->failure_time(intact) == 0.75);
    CHECK(st->damage(intact) == 1.0);
    for (double& x : m->nodes.x) x *= 1.0 + 1e-6;  // a small stretch of everything
    std::fill(m->nodes.f.begin(), m->nodes.f.end(), 0.0);
  }
  const JointStepSummary a = stage.add_forces(model, 1.0, kStep),
                         b = rebound.add_forces(copy, 1.0, kStep);
  CHECK(a.newly_broken == 0);  // the marked joint broke before: not new
  CHECK(a.broken == b.broken);
  CHECK(std::memcmp(model.nodes.f.data(), copy.nodes.f.data(),
                    model.nodes.f.size() * sizeof(double)) == 0);
  CHECK(std::memcmp(&a.stored_energy, &b.stored_energy, sizeof(double)) == 0);
}

TEST_CASE(
    "joint stage: pristine joints keep no state, those that damage get a full history, and the "
    "forces and energies equal joint_force on full histories",
    "[fracture][stage]") {
  Model model = jointed_column();
  JointStage stage(model);
  set_lift_velocity(model);
  CHECK(stage.live_histories() == 0);
  // Reference: every joint computed by joint_force with a full JointHistory of its own.
  JointStage full_laws(model);
  std::vector<JointHistory> reference(static_cast<std::size_t>(model.joints.size()));
  const auto reference_forces = [&](double& stored, double& fracture) {
    std::vector<double> f(model.nodes.f.size(), 0.0);
    stored = fracture = 0.0;
    for (LocalIndex j = 0; j < model.joints.size(); ++j) {
      if (reference[j].broken) continue;
      Vec3 x[6];
      for (int i = 0; i < 6; ++i)
        x[i] = vec3_at(model.nodes.x.data(), model.joints.nodes[6 * j + i]);
      const JointForce jf = joint_force(x, model.joints.area0[j],
                                        full_laws.laws()[model.joints.law[j]], reference[j]);
      for (int i = 0; i < 6; ++i) vec3_at(f.data(), model.joints.nodes[6 * j + i]) += jf.force[i];
      stored += jf.stored_energy;
      fracture += jf.fracture_energy;
    }
    return f;
  };
  // The upper cell pulled up in 2.5 µm steps: the joints between the cells stay below their peak
  // opening in the first steps, then damage and break; the joints inside the cells stay pristine.
  std::size_t live_before_break = 0;
  for (int step = 1; step <= 120; ++step) {
    for (LocalIndex t = 0; t < model.tets.size(); ++t)
      if (upper(model, t))
        for (int c = 0; c < 4; ++c)
          model.nodes.x[3 * static_cast<std::size_t>(model.tets.nodes[4 * t + c]) + 2] += kLift;
    double stored = 0.0, fracture = 0.0;
    const std::vector<double> f_reference = reference_forces(stored, fracture);
    std::fill(model.nodes.f.begin(), model.nodes.f.end(), 0.0);
    const JointStepSummary s = stage.add_forces(model, 0.001 * step, kStep);
    for (LocalIndex j : stage.newly_broken()) reference[j].broken = true;
    INFO("step " << step);
    REQUIRE(std::memcmp(model.nodes.f.data(), f_reference.data(),
                        f_reference.size() * sizeof(double)) == 0);
    CHECK(std::memcmp(&s.stored_energy, &stored, sizeof(double)) == 0);
    // Forces and stored energy bit for bit.  The dissipation of the step in which a joint leaves
    // the pristine state starts from the previous step's opening and shear, which the stage
    // rebuilds from x − step·v (the reference kept them): equal to round-off of the positions.
    CHECK(s.fracture_dissipated == Approx(fracture).epsilon(1e-9).margin(1e-300));
    if (step == 1) CHECK(stage.live_histories() == 0);
    if (s.broken == 0) live_before_break = stage.live_histories();
  }
  // Only the joints between the cells left the pristine state; history() writes all of them out
  // (the pristine ones as fresh histories: they keep no state).
  long across = 0;
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    across += upper(model, model.joints.tets[2 * j]) != upper(model, model.joints.tets[2 * j + 1]);
  CHECK(std::count_if(reference.begin(), reference.end(),
                      [](const JointHistory& h) { return h.broken; }) == across);
  CHECK(live_before_break == static_cast<std::size_t>(across));
  CHECK(stage.live_histories() == static_cast<std::size_t>(across));
  CHECK(stage.live_histories() < static_cast<std::size_t>(model.joints.size()));
  const std::vector<JointHistory> written = stage.history();
  REQUIRE(written.size() == reference.size());
  for (std::size_t j = 0; j < written.size(); ++j) {
    CHECK(written[j].broken == reference[j].broken);
    if (pristine(reference[j])) {
      CHECK(pristine(written[j]));
      for (int i = 0; i < 3; ++i)
        CHECK((written[j].point[i].damage == 0.0 && written[j].point[i].previous_opening == 0.0 &&
               written[j].point[i].previous_shear_sq == 0.0));
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      CHECK(written[j].point[i].damage == reference[j].point[i].damage);
      CHECK(written[j].point[i].previous_opening == reference[j].point[i].previous_opening);
      CHECK(written[j].point[i].previous_shear_sq == reference[j].point[i].previous_shear_sq);
    }
  }
}
