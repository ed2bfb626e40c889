// The contact stage keys friction history by the two tets' 64-bit global ids: a model whose ids
// lie above 2^32 (a model of more than four billion tets, or ids offset for a test) keeps and
// hands back each pair's history under its own ids.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <utility>
#include <vector>

#include "contact/contact_stage.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "core/model_builder.hpp"

using namespace fdem;

namespace {

// A box of 6 Kuhn tets (one cell), corners lo and hi.
BodyMesh cell(const Vec3& lo, const Vec3& hi) {
  BodyMesh mesh;
  mesh.source = "test";
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        for (int d = 0; d < 3; ++d) {
          const int bit = d == 0 ? i : d == 1 ? j : k;
          mesh.coords.push_back(bit ? hi[d] : lo[d]);
        }
  // Kuhn subdivision along the diagonal 0–7, positively oriented.
  const LocalIndex tets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                 {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  for (const auto& t : tets) mesh.tets.insert(mesh.tets.end(), t, t + 4);
  return mesh;
}

BodySpec body(const std::string& name) {
  BodySpec b;
  b.name = name;
  b.material = 0;
  return b;
}

// A block resting on a base, both one cell of stone with friction coefficient `friction`.
Model block_on_base(double friction) {
  Scene scene;
  scene.source_path = "test";
  MaterialSpec stone;
  stone.name = "stone";
  stone.density = 2500;
  stone.elastic.young = 1e8;
  stone.elastic.poisson = 0.2;
  stone.contact.friction = friction;
  scene.materials.push_back(stone);
  scene.bodies = {body("base"), body("block")};
  return build_model(scene, {cell(Vec3(0, 0, 0), Vec3(1, 1, 0.2)),
                             cell(Vec3(0.2, 0.2, 0.199), Vec3(0.7, 0.7, 0.5))});
}

}  // namespace

TEST_CASE("friction history keyed by global ids above 2^32 survives re-detection",
          "[contact][stage]") {
  Model model = block_on_base(0.6);
  const GlobalId offset = GlobalId{1} << 33;  // ids above 2^32, low 32 bits equal to the old ones
  for (GlobalId& g : model.tets.gid) g += offset;
  for (GlobalId& g : model.nodes.gid) g += offset;
  build_tet_force_order(model.tets, model.tet_force_order);

  ContactStage stage(model, ContactSettings{0.02});
  stage.detect(model);
  REQUIRE(!stage.candidates().empty());
  std::vector<FrictionEntry> entries;
  for (const CandidatePair& p : stage.candidates()) {
    FrictionEntry e;
    e.a = model.tets.gid[p.a];
    e.b = model.tets.gid[p.b];
    e.spring = Vec3(1e-6, -2e-6, 0.0);
    e.stiffness = 3e5;
    entries.push_back(e);
  }
  stage.rebind(model, model.nodes.x, {}, entries, true);  // repeats the detection
  const std::vector<FrictionEntry> back = stage.friction_entries();
  REQUIRE(back.size() == entries.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    CHECK(back[i].a == entries[i].a);
    CHECK(back[i].b == entries[i].b);
    CHECK(back[i].a >= offset);
    CHECK(back[i].spring == entries[i].spring);
    CHECK(back[i].stiffness == entries[i].stiffness);
  }
}

TEST_CASE("friction entries travel as pair records and come back bit for bit", "[contact][state]") {
  std::vector<FrictionEntry> entries(3);
  entries[0] = {1, 2, Vec3(1e-7, -2e-9, 3.5e-12), 4.2e8};
  entries[1] = {(GlobalId{1} << 33) + 5, (GlobalId{1} << 34), Vec3(-0.0, 1.0 / 3.0, 2e-300), 1.0};
  entries[2] = {9, 10, Vec3::Zero(), 0.0};
  const std::vector<PairRecord> records = friction_records(entries);
  REQUIRE(records.size() == 3);
  CHECK(records[1].a == entries[1].a);
  CHECK(records[0].value[3] == 4.2e8);
  const std::vector<FrictionEntry> back = friction_entries(records);
  REQUIRE(back.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(back[i].a == entries[i].a);
    CHECK(back[i].b == entries[i].b);
    CHECK(std::memcmp(back[i].spring.data(), entries[i].spring.data(), 3 * sizeof(double)) == 0);
    CHECK(back[i].stiffness == entries[i].stiffness);
  }
}

TEST_CASE("a bonded pair never pairs, and pairs again as soon as its bond is released",
          "[contact][stage]") {
  const Model model = block_on_base(0.0);
  const auto pairs_of = [](const ContactStage& stage) {
    std::vector<std::pair<LocalIndex, LocalIndex>> out;
    for (const CandidatePair& p : stage.candidates()) out.emplace_back(p.a, p.b);
    std::sort(out.begin(), out.end());
    return out;
  };
  ContactStage free_stage(model, ContactSettings{0.02});
  free_stage.detect(model);
  const auto all = pairs_of(free_stage);
  REQUIRE(all.size() >= 2);

  ContactStage stage(model, ContactSettings{0.02});
  const std::pair<LocalIndex, LocalIndex> bonded = all[1];
  stage.set_bonds(model.tets.size(), {bonded});
  CHECK(stage.detect_if_needed(model));  // never detected: runs
  auto expected = all;
  expected.erase(std::find(expected.begin(), expected.end(), bonded));
  CHECK(pairs_of(stage) == expected);          // every pair but the bonded one
  CHECK_FALSE(stage.detect_if_needed(model));  // nothing moved: no detection due
  const std::vector<std::uint8_t> states = stage.tet_joint_states();
  CHECK(states[bonded.first] == static_cast<std::uint8_t>(TetJointState::intact));

  // The bricks moved since the detection: the freed pair is found at the positions of the last
  // detection, which stay, and no detection falls due.
  Model moved = model;
  for (double& x : moved.nodes.x) x += 1e-4;
  const std::vector<double> at_detection = stage.positions_at_detection(model);
  const long detections = stage.detections();
  stage.release_bonds(moved, {{bonded.first, -1}});  // the other tet on another rank: cracked
  CHECK(stage.tet_joint_states()[bonded.first] ==
        static_cast<std::uint8_t>(TetJointState::cracked));
  CHECK(pairs_of(stage) == expected);  // still bonded to its partner
  stage.release_bonds(moved, {{bonded.first, bonded.second}});
  CHECK(pairs_of(stage) == all);
  CHECK(stage.tet_joint_states()[bonded.second] ==
        static_cast<std::uint8_t>(TetJointState::cracked));
  CHECK(stage.positions_at_detection(model) == at_detection);
  CHECK(stage.detections() == detections);
  CHECK_FALSE(stage.detection_due(moved));  // 0.1 mm < buffer / 2

  // Released before any detection: the first detection finds it.
  ContactStage fresh(model, ContactSettings{0.02});
  fresh.set_bonds(model.tets.size(), {bonded});
  fresh.release_bonds(model, {bonded});
  CHECK(fresh.detect_if_needed(model));
  CHECK(pairs_of(fresh) == all);
}

namespace {

// Moves every node of the block (piece 1) by `by`.
void move_block(Model& model, const Vec3& by) {
  std::vector<std::uint8_t> moved(static_cast<std::size_t>(model.nodes.size()), 0);
  for (LocalIndex t = 0; t < model.tets.size(); ++t) {
    if (model.tets.piece[t] != 1) continue;
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = model.tets.nodes[4 * t + c];
      if (!moved[n]) vec3_at(model.nodes.x.data(), n) += by;
      moved[n] = 1;
    }
  }
}

}  // namespace

// The stage computes each tet's geometry once per step and finds it through per-pair slots that
// must follow every change of the candidate list: its forces must be the kernel's on each pair
// from the corners, summed in the same order, bit for bit, before and after the list changes.
TEST_CASE("contact forces equal the kernel's pair by pair while the candidate list changes",
          "[contact][stage]") {
  Model model = block_on_base(0.0);
  ContactStage stage(model, ContactSettings{0.02});
  const double penalty = stage.material_penalty()[0];
  const double tolerance = ContactSettings{}.sliver_tolerance;
  const auto kernel_forces = [&] {
    std::vector<double> f(model.nodes.f.size(), 0.0);
    for (const CandidatePair& p : stage.candidates()) {
      const ContactPairResult r =
          potential_contact(tet_corners(model, p.a), tet_corners(model, p.b), penalty, tolerance);
      if (!r.overlapping) continue;
      for (int c = 0; c < 4; ++c) {
        vec3_at(f.data(), model.tets.nodes[4 * p.a + c]) += r.force_contactor[c];
        vec3_at(f.data(), model.tets.nodes[4 * p.b + c]) += r.force_target[c];
      }
    }
    return f;
  };
  const auto step = [&] {
    std::fill(model.nodes.f.begin(), model.nodes.f.end(), 0.0);
    stage.detect_if_needed(model);
    const ContactForceSummary summary = stage.add_forces(model, 1e-6);
    CHECK(model.nodes.f == kernel_forces());
    return summary.active_pairs;
  };
  CHECK(step() > 0);  // pressed 1 mm into the base
  const std::vector<CandidatePair> first = stage.candidates();
  move_block(model, Vec3(0.25, 0.0, 0.0));  // further than buffer / 2: a new list
  CHECK(step() > 0);
  CHECK(stage.detections() == 2);
  CHECK(stage.candidates() != first);
  move_block(model, Vec3(0.0, 0.0, 0.005));  // lifted clear, no detection due
  CHECK(step() == 0);
  CHECK(stage.detections() == 2);
}

// A lasting contact's friction history is looked up once and then held by the pair; parting
// erases it (and the pair's hold on it), meeting again starts a new one, and a new list starts
// afresh.  Under the sanitizers a stale hold would be a use after free.
TEST_CASE("a stick spring ends when its pair parts and starts afresh when the pair meets again",
          "[contact][stage]") {
  Model model = block_on_base(0.6);
  ContactStage stage(model, ContactSettings{0.02});
  stage.detect(model);
  const auto entries_after_step = [&] {
    stage.detect_if_needed(model);
    stage.add_forces(model, 1e-6);
    return stage.friction_entries();
  };
  const std::vector<FrictionEntry> pressed = entries_after_step();
  REQUIRE(!pressed.empty());
  CHECK(entries_after_step().size() == pressed.size());  // held: the same pairs
  move_block(model, Vec3(0.0, 0.0, 0.005));              // parted (no detection due)
  CHECK(entries_after_step().empty());
  move_block(model, Vec3(0.0, 0.0, -0.005));  // pressed again
  const std::vector<FrictionEntry> again = entries_after_step();
  REQUIRE(again.size() == pressed.size());
  for (std::size_t i = 0; i < again.size(); ++i) {
    CHECK(again[i].a == pressed[i].a);
    CHECK(again[i].b == pressed[i].b);
    CHECK(again[i].stiffness == pressed[i].stiffness);
  }
  move_block(model, Vec3(0.25, 0.0, 0.0));  // a new list: every history of a pair still in it
  const long detections = stage.detections();
  const std::vector<FrictionEntry> moved = entries_after_step();
  CHECK(stage.detections() == detections + 1);
  CHECK(!moved.empty());
  for (const FrictionEntry& e : moved) {
    const auto in_list = std::any_of(
        stage.candidates().begin(), stage.candidates().end(), [&](const CandidatePair& p) {
          return model.tets.gid[p.a] == e.a && model.tets.gid[p.b] == e.b;
        });
    CHECK(in_list);
  }
  CHECK(entries_after_step().size() == moved.size());
}
