// Checkpoint rows from the field tables and back (parallel/checkpoint_fields): the owned entries'
// checkpoint fields, the stages' node fields, joint records and pair records, keyed by
// gid − gid_offset; stored back into the entries held, the rest left alone.
#include <catch2/catch.hpp>
#include <variant>

#include "core/fields.hpp"
#include "parallel/checkpoint_fields.hpp"

using namespace fdem;

namespace {

// Four nodes (three owned), three tets (the first two owned), two joints (tet A of the first is
// owned, of the second not), joint records of 5 bytes, three pairs (tet a held for two, owned for
// one).
struct Held {
  Model model;
  TravellingState state;
};

Held make_held(double seed) {
  Held h;
  Model& m = h.model;
  m.gid_offset = 1000;
  m.nodes.resize(4);
  m.nodes.n_owned = 3;
  for (LocalIndex n = 0; n < 4; ++n) {
    m.nodes.gid[n] = 1000 + 10 * n;
    const double reference[3] = {3.0 * seed, 3.0 * seed, 3.0 * seed};  // not checkpointed
    m.nodes.add_reference(n, reference);
    for (int k = 0; k < 3; ++k) {
      m.nodes.x[3 * n + k] = seed + n + 0.1 * k;
      m.nodes.v[3 * n + k] = seed - n - 0.1 * k;
      m.nodes.prescribed_velocity[3 * n + k] = seed * 0.5 + n;
    }
  }
  m.tets.resize(3);
  m.tets.gid = {1000, 1001, 1002};
  m.tets.n_owned = 2;
  m.tets.owned = {1, 1, 0};
  m.tets.active = {1, 1, 1};
  m.joints.resize(2);
  m.joints.gid = {1000, 1001};
  m.joints.tets = {0, 1, 2, 1};
  m.joints.broken = {1, 0};
  m.joints.mode = {2, 0};
  m.joints.area0 = {3.0, 3.0};
  h.state.x_at_detection.resize(12);
  for (std::size_t i = 0; i < 12; ++i) h.state.x_at_detection[i] = seed * 2.0 + double(i);
  h.state.joint_record_bytes = 5;
  h.state.joint_records.resize(10);
  for (std::size_t i = 0; i < 10; ++i)
    h.state.joint_records[i] = static_cast<std::uint8_t>(seed * 10 + double(i));
  h.state.pairs = {{1000, 1001, {seed, 1.0, 2.0, 3.0}},
                   {1001, 1002, {seed, 4.0, 5.0, 6.0}},
                   {1002, 1005, {seed, 7.0, 8.0, 9.0}}};
  return h;
}

}  // namespace

TEST_CASE(
    "checkpoint fields: the owned entries' checkpoint fields and the stages' records, "
    "keyed by gid less the offset",
    "[parallel][checkpoint]") {
  const Held h = make_held(1.0);
  const CheckpointRows rows = owned_checkpoint_rows(h.model, h.state);
  CHECK(rows.field_list() == checkpoint_layout(5).field_list());
  CHECK(rows.nodes.gid == std::vector<GlobalId>{0, 10, 20});
  CHECK(std::get<std::vector<double>>(rows.nodes.column("x").values).size() == 9);
  CHECK(std::get<std::vector<double>>(rows.nodes.column("x_at_detection").values)[3] == 5.0);
  CHECK(rows.joints.gid == std::vector<GlobalId>{0});  // the second one's tet A is not owned
  CHECK(std::get<std::vector<std::uint8_t>>(rows.joints.column("history").values).size() == 5);
  CHECK(rows.pair_a == std::vector<GlobalId>{0, 1});  // tet a owned
  CHECK(rows.pair_b == std::vector<GlobalId>{1, 2});
  CHECK(std::get<std::vector<double>>(rows.pair_columns[0].values) ==
        std::vector<double>{1.0, 1.0, 2.0, 1.0, 4.0, 5.0});
  CHECK(std::get<std::vector<double>>(rows.pair_columns[1].values) ==
        std::vector<double>{3.0, 6.0});
}

TEST_CASE(
    "checkpoint fields: rows stored back restore every checkpoint field of the entries "
    "held and leave the others alone",
    "[parallel][checkpoint]") {
  const Held written = make_held(1.0);
  // Every row of the whole model (as a reader on one rank gets them).
  Held everything = written;
  everything.model.tets.owned.clear();
  everything.model.tets.active.clear();
  everything.model.nodes.n_owned = 4;
  const CheckpointRows rows = owned_checkpoint_rows(everything.model, everything.state);

  Held restored = make_held(5.0);
  store_checkpoint_rows(rows, restored.model, restored.state);
  const NodeArrays& a = written.model.nodes;
  const NodeArrays& b = restored.model.nodes;
  CHECK(b.x == a.x);
  CHECK(b.v == a.v);
  CHECK(b.prescribed_velocity == a.prescribed_velocity);
  CHECK(b.reference_positions == make_held(5.0).model.nodes.reference_positions);  // left alone
  CHECK(b.reference_positions != a.reference_positions);
  CHECK(restored.state.x_at_detection == written.state.x_at_detection);
  CHECK(restored.model.joints.broken == written.model.joints.broken);
  CHECK(restored.model.joints.mode == written.model.joints.mode);
  CHECK(restored.state.joint_records == written.state.joint_records);
  // Every pair whose tet a is held (1005 is no tet here, but 1002 is: its pair comes back).
  REQUIRE(restored.state.pairs.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(restored.state.pairs[i].a == written.state.pairs[i].a);
    CHECK(restored.state.pairs[i].value[0] == 1.0);
  }
}

TEST_CASE(
    "checkpoint fields: without prescribed velocities (no velocity load) the column holds zeros "
    "and restores into a model without them",
    "[parallel][checkpoint]") {
  Held written = make_held(1.0);
  written.model.nodes.has_prescribed_velocity = false;
  written.model.nodes.resize(4);  // drops the array
  REQUIRE(written.model.nodes.prescribed_velocity.empty());
  const CheckpointRows rows = owned_checkpoint_rows(written.model, written.state);
  CHECK(rows.field_list() == checkpoint_layout(5).field_list());
  CHECK(std::get<std::vector<double>>(rows.nodes.column("prescribed_velocity").values) ==
        std::vector<double>(9, 0.0));
  CHECK(std::get<std::vector<double>>(rows.nodes.column("x").values).size() == 9);

  Held restored = make_held(5.0);
  restored.model.nodes.has_prescribed_velocity = false;
  restored.model.nodes.resize(4);
  store_checkpoint_rows(rows, restored.model, restored.state);
  CHECK(restored.model.nodes.prescribed_velocity.empty());
  for (LocalIndex n = 0; n < 3; ++n)
    for (int k = 0; k < 3; ++k) {
      CHECK(restored.model.nodes.x[3 * n + k] == written.model.nodes.x[3 * n + k]);
      CHECK(restored.model.nodes.prescribed_velocity_at(3 * n + k) == 0.0);
    }
}
