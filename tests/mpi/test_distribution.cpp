// The distribution's invariants on N ranks, checked against the whole model every rank builds
// here: each tet owned once, every tet that touches an owned node held, ghost nodes owned by the
// owner of their first tet, and each owner's list of where its tets have copies — the list an
// incremental migration sends against — true.  After nodes move, an incremental cycle gives the
// rank the same arrays, bit for bit, as a full one.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/model_builder.hpp"
#include "drivers/scene_builders.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"

using namespace fdem;

namespace {

// A long slab with a post standing on it, nodes displaced a little off the mesh.
Model slab_and_post() {
  Scene scene = builders::basic_scene(1.0);
  scene.materials = {builders::elastic_material(1000, 1e6, 0.3)};
  scene.bodies = {builders::box_body("slab", {0, 0, 0}, {4, 0.6, 0.2}, 32, 5, 2, 0),
                  builders::box_body("post", {0.2, 0.2, 0.21}, {0.4, 0.4, 1.0}, 2, 2, 6, 0)};
  Model model = build_model(scene, load_body_meshes(scene));
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    for (int k = 0; k < 3; ++k)
      model.nodes.x[3 * i + k] +=
          1e-3 * std::sin(0.7 * static_cast<double>(model.nodes.gid[i]) + k);
  return model;
}

// Moves every node of `model` (owned and ghost: as the halo exchange leaves them) by a function
// of its gid and of `shift`: the post (above z = 0.205) slides along x by `shift`.
void move(Model& model, double shift) {
  NodeArrays& n = model.nodes;
  for (LocalIndex i = 0; i < n.size(); ++i) {
    const double g = static_cast<double>(n.gid[i]);
    if (n.x0(i)[2] > 0.205) n.x[3 * i] += shift;
    for (int k = 0; k < 3; ++k) n.x[3 * i + k] += 1e-4 * std::cos(0.3 * g + k);
  }
}

// The invariants of `local` (this rank's part of `global`) under `d`.
void check_invariants(const Communicator& comm, const Model& global, const Model& local,
                      const Distribution& d) {
  const int me = comm.rank();
  const TetArrays& tets = local.tets;
  const NodeArrays& nodes = local.nodes;
  // Each tet owned by exactly one rank.
  std::vector<GlobalId> owned;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t)) owned.push_back(tets.gid[t]);
  CHECK(static_cast<LocalIndex>(owned.size()) == tets.n_owned);
  struct TetOwner {
    GlobalId gid;
    std::int32_t rank;
  };
  std::vector<TetOwner> mine;
  for (GlobalId g : owned) mine.push_back({g, me});
  std::vector<TetOwner> all = comm.allgatherv(mine);
  std::sort(all.begin(), all.end(),
            [](const TetOwner& a, const TetOwner& b) { return a.gid < b.gid; });
  REQUIRE(static_cast<LocalIndex>(all.size()) == global.tets.size());
  std::map<GlobalId, int> owner_of;
  for (LocalIndex t = 0; t < global.tets.size(); ++t) {
    CHECK(all[t].gid == global.tets.gid[t]);  // every gid once
    owner_of[all[t].gid] = all[t].rank;
  }
  // Local tets in ascending gid; owned nodes first, each range in ascending gid.
  CHECK(std::is_sorted(tets.gid.begin(), tets.gid.end()));
  CHECK(std::is_sorted(nodes.gid.begin(), nodes.gid.begin() + nodes.n_owned));
  CHECK(std::is_sorted(nodes.gid.begin() + nodes.n_owned, nodes.gid.end()));
  // Each node's first tet (smallest gid that uses it) owns it.
  std::map<GlobalId, GlobalId> first_tet;
  std::map<GlobalId, std::vector<GlobalId>> tets_of_node;
  for (LocalIndex t = 0; t < global.tets.size(); ++t)
    for (int c = 0; c < 4; ++c) {
      const GlobalId n = global.nodes.gid[global.tets.nodes[4 * t + c]];
      tets_of_node[n].push_back(global.tets.gid[t]);
      if (!first_tet.count(n)) first_tet[n] = global.tets.gid[t];  // global tets in gid order
    }
  const std::vector<std::int32_t>& node_owner = d.node_owners();
  REQUIRE(static_cast<LocalIndex>(node_owner.size()) == nodes.size());
  long wrong_owner = 0, missing_neighbour = 0;
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    const int expected = owner_of[first_tet[nodes.gid[n]]];
    if (node_owner[n] != expected || (n < nodes.n_owned) != (expected == me)) ++wrong_owner;
    // Held neighbours: every tet touching an owned node is here (its force on the node).
    if (n < nodes.n_owned)
      for (GlobalId t : tets_of_node[nodes.gid[n]])
        if (tets.find(t) < 0) ++missing_neighbour;
  }
  CHECK(wrong_owner == 0);
  CHECK(missing_neighbour == 0);
  // Active tets: owned or touching an owned node.
  long wrong_active = 0;
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    bool touches = false;
    for (int c = 0; c < 4; ++c) touches = touches || tets.nodes[4 * t + c] < nodes.n_owned;
    if (static_cast<bool>(tets.active[t]) != (tets.is_owned(t) || touches)) ++wrong_active;
  }
  CHECK(wrong_active == 0);
  // Each owner knows where its tets have copies: the same list as the copies every rank holds.
  struct Copy {
    GlobalId gid;
    std::int32_t rank;
  };
  std::vector<Copy> held;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (!tets.is_owned(t)) held.push_back({tets.gid[t], me});
  std::vector<std::pair<GlobalId, std::int32_t>> copies;
  for (const Copy& c : comm.allgatherv(held))
    if (owner_of[c.gid] == me) copies.emplace_back(c.gid, c.rank);
  std::sort(copies.begin(), copies.end());
  CHECK(copies == d.copies_elsewhere());
}

// The arrays a migration rebuilds, as bytes.
std::vector<char> local_bytes(const Model& m) {
  std::vector<char> out;
  const auto add = [&](const auto& v) {
    const auto* p = reinterpret_cast<const char*>(v.data());
    out.insert(out.end(), p, p + v.size() * sizeof(v[0]));
  };
  add(m.tets.gid);
  add(m.tets.nodes);
  add(m.tets.owned);
  add(m.tets.active);
  add(m.nodes.gid);
  add(m.nodes.x);
  add(m.nodes.v);
  add(m.nodes.mass);
  add(m.tet_force_order);
  out.push_back(static_cast<char>(m.nodes.n_owned % 127));
  return out;
}

}  // namespace

TEST_CASE("distribution invariants: tets owned once, neighbours held, ghost owners, copies known",
          "[mpi][distribution]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const Model global = slab_and_post();
  const double buffer = 0.02;  // m
  const auto start = [&](bool incremental, Model& local, TravellingState& state) {
    DistributionSettings settings;
    settings.incremental = incremental;
    TravellingState whole;
    whole.x_at_detection = global.nodes.x;
    return Distribution(comm, settings, global, whole, buffer, {}, local, state);
  };
  Model a_model, b_model;
  TravellingState a_state, b_state;
  Distribution incremental = start(true, a_model, a_state);
  Distribution full = start(false, b_model, b_state);
  check_invariants(comm, global, a_model, incremental);
  CHECK(local_bytes(a_model) == local_bytes(b_model));

  // The post slides over the slab in three cycles: copies enter and leave halos.
  for (int cycle = 0; cycle < 3; ++cycle) {
    INFO("cycle " << cycle);
    for (Model* m : {&a_model, &b_model}) move(*m, 0.9);
    a_state.x_at_detection = a_model.nodes.x;  // a detection at these positions follows
    b_state.x_at_detection = b_model.nodes.x;
    incremental.redistribute(a_model, a_state, {}, 0.0);
    full.redistribute(b_model, b_state, {}, 0.0);
    check_invariants(comm, global, a_model, incremental);
    CHECK(local_bytes(a_model) == local_bytes(b_model));
    CHECK(incremental.report().rebalances == 0);  // the weights stay balanced: no re-partition
  }
  const MigrationReport& inc = incremental.report().migration;
  const MigrationReport& ref = full.report().migration;
  CHECK(inc.incremental_cycles == 3);
  CHECK(ref.incremental_cycles == 0);
  if (comm.size() > 1) {
    CHECK(inc.sent_tets + inc.dropped_tets > 0);  // the halos changed
    CHECK(inc.sent_tets < ref.sent_tets);         // and only the changes travelled
    CHECK(inc.sent_bytes < ref.sent_bytes);
  }
}

TEST_CASE("distribution invariants hold after re-partitions at random", "[mpi][distribution]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const Model global = slab_and_post();
  DistributionSettings settings;
  settings.random_parts = true;
  settings.rebalance_threshold = 0.0;  // re-partition at every cycle
  TravellingState whole, state;
  whole.x_at_detection = global.nodes.x;
  Model local;
  Distribution d(comm, settings, global, whole, 0.02, {}, local, state);
  for (int cycle = 0; cycle < 2; ++cycle) {
    INFO("cycle " << cycle);
    move(local, 0.1);
    state.x_at_detection = local.nodes.x;
    d.redistribute(local, state, {}, 0.0);
    check_invariants(comm, global, local, d);
  }
  if (comm.size() > 1) CHECK(d.report().rebalances == 2);
}

TEST_CASE(
    "re-partition on measured cost: only when the busiest rank's excess pays for the last one",
    "[mpi][distribution]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const Model global = slab_and_post();
  DistributionSettings settings;
  settings.rebalance_threshold = 0.0;  // the weights always call for a re-partition
  TravellingState whole, state;
  whole.x_at_detection = global.nodes.x;
  Model local;
  Distribution d(comm, settings, global, whole, 0.02, {}, local, state);
  // Busy seconds since the last cycle: even, then rank 0 far busier (100 s against 1 s: far more
  // than any re-partition of this model costs), then even again.
  const double busy[4] = {1.0, 1.0, comm.rank() == 0 ? 100.0 : 1.0, 1.0};
  long rebalances[4], declined[4];
  for (int cycle = 0; cycle < 4; ++cycle) {
    state.x_at_detection = local.nodes.x;
    d.redistribute(local, state, {}, busy[cycle]);
    rebalances[cycle] = d.report().rebalances;
    declined[cycle] = d.report().migration.repartitions_declined;
  }
  const DistributionReport& r = d.report();
  if (comm.size() == 1) {  // nothing to re-partition
    CHECK(r.rebalances == 0);
    return;
  }
  CHECK(rebalances[0] == 1);  // the first goes ahead: no re-partition was timed yet
  CHECK(declined[1] == 1);    // even load: no gain
  CHECK(rebalances[1] == 1);
  CHECK(rebalances[2] == 2);  // 99 s over the mean on rank 0 pays for it
  CHECK(declined[2] == 1);
  CHECK(declined[3] == 2);
  const MigrationReport& m = r.migration;
  CHECK(m.last_repartition_seconds > 0.0);
  CHECK(m.last_repartition_seconds < 1.0);
  CHECK(m.predicted_gain_seconds > 40.0);  // cycle 2: 100 − mean of (100, 1, …)
  CHECK(m.measured_imbalance == Approx(1.0));
  CHECK(m.incremental_cycles == 2);
}

TEST_CASE(
    "without contact the step's exchange brings every ghost the forces read, a redistribution "
    "every ghost",
    "[mpi][distribution]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const Model global = slab_and_post();
  TravellingState whole, state;
  whole.x_at_detection = global.nodes.x;
  Model local;
  Distribution d(comm, DistributionSettings{}, global, whole, 0.0, {}, local, state);
  NodeArrays& nodes = local.nodes;
  const auto value = [](GlobalId gid, int k) { return 10.0 + 0.25 * static_cast<double>(gid) + k; };
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)  // the owners move their nodes; ghosts lag
    for (int k = 0; k < 3; ++k) nodes.x[3 * n + k] = value(nodes.gid[n], k);
  d.start_halo_exchange(nodes);
  d.finish_halo_exchange(nodes);
  // Every node of every tet that touches a node of an owned tet is current.
  std::vector<std::uint8_t> of_owned(static_cast<std::size_t>(nodes.size()), 0);
  const TetArrays& tets = local.tets;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t))
      for (int c = 0; c < 4; ++c) of_owned[tets.nodes[4 * t + c]] = 1;
  long stale_read = 0, stale_other = 0;
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    bool read = false;
    for (int c = 0; c < 4; ++c) read = read || of_owned[tets.nodes[4 * t + c]];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      if (nodes.x[3 * n] != value(nodes.gid[n], 0)) (read ? stale_read : stale_other) += 1;
    }
  }
  CHECK(stale_read == 0);
  const DistributionReport& r = d.report();
  if (comm.size() > 1) {
    CHECK(r.exchanged_ghosts_sum < r.ghost_nodes_sum);  // the halo holds more than the step reads
    CHECK(comm.sum(static_cast<std::int64_t>(stale_other)) > 0);
  }
  // A redistribution decides from every held tet: every ghost is brought up to date first.
  state.x_at_detection = nodes.x;
  d.redistribute(local, state, {}, 0.0);
  long stale = 0;
  for (LocalIndex n = 0; n < local.nodes.size(); ++n)
    for (int k = 0; k < 3; ++k) stale += local.nodes.x[3 * n + k] != value(local.nodes.gid[n], k);
  CHECK(stale == 0);
}

namespace {

// A jointed bar (a cohesive joint on every interior face), its nodes displaced a little.
Model jointed_bar() {
  Scene scene = builders::basic_scene(1.0);
  MaterialSpec rock = builders::elastic_material(2600, 1e9, 0.25);
  rock.fracture = builders::fracture_spec();
  scene.materials = {rock};
  BodySpec bar = builders::box_body("bar", {0, 0, 0}, {2.0, 0.2, 0.2}, 20, 2, 2, 0);
  bar.joints = JointPlacement::all;
  scene.bodies = {bar};
  Model model = build_model(scene, load_body_meshes(scene));
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    for (int k = 0; k < 3; ++k)
      model.nodes.x[3 * i + k] +=
          1e-4 * std::sin(0.7 * static_cast<double>(model.nodes.gid[i]) + k);
  return model;
}

}  // namespace

TEST_CASE(
    "a record about a tet reaches every rank that holds a copy of it and no other, and the owners "
    "of both tets of a joint hold it",
    "[mpi][distribution]") {
  const Communicator comm = Communicator::world();
  const int me = comm.rank();
  INFO("rank " << me << " of " << comm.size());
  const Model global = jointed_bar();
  REQUIRE(global.joints.size() > 0);
  for (const bool incremental : {true, false}) {
    INFO((incremental ? "incremental" : "full") << " migration");
    DistributionSettings settings;
    settings.incremental = incremental;
    settings.random_parts = true;        // owners scattered: many copies, on every rank
    settings.rebalance_threshold = 0.0;  // a re-partition at every cycle
    TravellingState whole, state;
    whole.x_at_detection = global.nodes.x;
    whole.tet_joint_state.assign(static_cast<std::size_t>(global.tets.size()), 1);
    Model local;
    Distribution d(comm, settings, global, whole, 0.01, {}, local, state);
    for (int cycle = 0; cycle < 3; ++cycle) {
      INFO("cycle " << cycle);
      if (cycle > 0) {
        state.x_at_detection = local.nodes.x;
        d.redistribute(local, state, {}, 0.0);
      }
      const TetArrays& tets = local.tets;
      // Both owners of a joint's tets hold it: each computes it and sees it break.
      std::map<GlobalId, int> sides_held;
      for (LocalIndex j = 0; j < local.joints.size(); ++j)
        for (int s = 0; s < 2; ++s) ++sides_held[tets.gid[local.joints.tets[2 * j + s]]];
      std::map<GlobalId, int> sides;
      for (LocalIndex j = 0; j < global.joints.size(); ++j)
        for (int s = 0; s < 2; ++s) ++sides[global.tets.gid[global.joints.tets[2 * j + s]]];
      long joints_missing = 0;
      for (LocalIndex t = 0; t < tets.size(); ++t)
        if (tets.is_owned(t)) joints_missing += sides[tets.gid[t]] - sides_held[tets.gid[t]];
      CHECK(joints_missing == 0);
      // Each owner tells about each of its tets: every copy hears once, from the owner.
      struct Notice {
        GlobalId tet;
        std::int32_t from;
      };
      std::vector<GlobalId> about;
      std::vector<Notice> notices;
      for (LocalIndex t = 0; t < tets.size(); ++t)
        if (tets.is_owned(t)) {
          about.push_back(tets.gid[t]);
          notices.push_back({tets.gid[t], me});
        }
      std::vector<char> bytes(notices.size() * sizeof(Notice));
      if (!bytes.empty()) std::memcpy(bytes.data(), notices.data(), bytes.size());
      const std::vector<char> arrived = d.send_to_holders(about, bytes, sizeof(Notice));
      REQUIRE(arrived.size() % sizeof(Notice) == 0);
      std::vector<GlobalId> heard;
      long wrong_sender = 0;
      for (std::size_t i = 0; i < arrived.size() / sizeof(Notice); ++i) {
        Notice n;
        std::memcpy(&n, arrived.data() + i * sizeof(Notice), sizeof(Notice));
        heard.push_back(n.tet);
        const LocalIndex t = tets.find(n.tet);
        if (t < 0 || tets.is_owned(t) || n.from == me) ++wrong_sender;
      }
      std::sort(heard.begin(), heard.end());
      std::vector<GlobalId> copies;
      for (LocalIndex t = 0; t < tets.size(); ++t)
        if (!tets.is_owned(t)) copies.push_back(tets.gid[t]);
      CHECK(wrong_sender == 0);
      CHECK(heard == copies);  // every copy once, nothing else
    }
  }
}

TEST_CASE(
    "candidate pairs travel with their tets: a migration between detections keeps the list a "
    "repeated detection gives, without the pass",
    "[mpi][distribution][contact]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const Model global = slab_and_post();
  const double buffer = 0.02;  // m: the post stands 0.01 m above the slab, inside it
  const auto gids = [](const Model& m, const ContactStage& stage) {
    std::vector<std::pair<GlobalId, GlobalId>> out;
    for (const CandidatePair& p : stage.candidates())
      out.emplace_back(m.tets.gid[p.a], m.tets.gid[p.b]);
    return out;
  };
  for (const bool repartition : {false, true}) {
    INFO((repartition ? "re-partition at every cycle" : "incremental cycles"));
    DistributionSettings settings;
    settings.random_parts = repartition;
    settings.rebalance_threshold = repartition ? 0.0 : 1.10;
    TravellingState whole, state;
    whole.x_at_detection = global.nodes.x;
    Model local;
    Distribution d(comm, settings, global, whole, buffer, {}, local, state);
    auto stage = std::make_unique<ContactStage>(local, ContactSettings{buffer});
    stage->detect(local);
    for (int cycle = 0; cycle < 3; ++cycle) {
      INFO("cycle " << cycle);
      move(local, 0.002);  // within buffer / 2 of the detection: no detection due
      state = TravellingState{};
      state.x_at_detection = stage->positions_at_detection(local);
      state.candidates = stage->candidate_gids(local);
      d.redistribute(local, state, {}, 0.0);
      // What travelled, against the detection repeated at the positions it saw.
      auto travelled = std::make_unique<ContactStage>(local, ContactSettings{buffer});
      travelled->rebind(local, state.x_at_detection, {}, {}, true, &state.candidates);
      ContactStage repeated(local, ContactSettings{buffer});
      repeated.rebind(local, state.x_at_detection, {}, {}, true);
      CHECK(gids(local, *travelled) == gids(local, repeated));
      CHECK(travelled->broad_phase_passes() == 0);
      CHECK(repeated.broad_phase_passes() == 1);
      CHECK(comm.sum(static_cast<std::int64_t>(travelled->candidates().size())) > 0);
      stage = std::move(travelled);
    }
    if (comm.size() > 1 && repartition) CHECK(d.report().rebalances == 3);
    if (!repartition) CHECK(d.report().migration.incremental_cycles == 3);
  }
}
