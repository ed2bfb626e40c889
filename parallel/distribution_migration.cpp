// Migration (parallel/distribution.hpp): rows packed for the ranks that need them, moved by the
// neighbour-only exchange, and the local model rebuilt from what a rank kept and what arrived —
// the full cycle (every copy) and the incremental one (only the copies that enter a halo).
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <utility>
#include <vector>

#include "core/checked_cast.hpp"
#include "core/error.hpp"
#include "parallel/distribution.hpp"
#include "parallel/distribution_rows.hpp"

namespace fdem {

using namespace distribution_rows;

namespace {

// Boxes span the positions at the last detection too (when the state has them): a rank repeats
// that detection after a migration (rebind), however far the nodes went since.
const std::vector<double>* detection_positions(const Model& model, const TravellingState& state) {
  return state.x_at_detection.size() == model.nodes.x.size() ? &state.x_at_detection : nullptr;
}

}  // namespace

// Packs lists[p] for every other rank p into `send` (grouped by rank; counts in 8-byte words),
// and lists[me] into `own` when given.  Returns the tet copies packed for other ranks.
long Distribution::pack_rows(const Model& model, const TravellingState& state,
                             const std::vector<std::vector<LocalIndex>>& lists,
                             std::vector<char>& send, std::vector<std::size_t>& send_counts,
                             std::vector<std::vector<char>>* own,
                             const std::vector<StartJoint>* start_joints, bool both_sides) const {
  const int ranks = comm_.size(), me = comm_.rank();
  send_counts.assign(static_cast<std::size_t>(ranks), 0);
  RowPacker packer(model, state, tet_owner_, node_owner_, node_first_tet_, start_joints,
                   both_sides);
  long copies = 0;
  for (int p = 0; p < ranks; ++p) {
    if (lists[p].empty()) continue;
    if (p == me) {
      if (!own) continue;
      // A tet's nodes (and joints) go with it into its chunk: a node shared by two chunks comes
      // twice and is stored once (assemble keeps one row per gid).
      const std::vector<LocalIndex>& mine = lists[p];
      for (std::size_t first = 0; first < mine.size(); first += own_chunk_tets) {
        const std::size_t last = std::min(mine.size(), first + own_chunk_tets);
        own->emplace_back();
        packer.pack(std::vector<LocalIndex>(mine.begin() + static_cast<std::ptrdiff_t>(first),
                                            mine.begin() + static_cast<std::ptrdiff_t>(last)),
                    own->back());
      }
      continue;
    }
    const std::size_t before = send.size();
    packer.pack(lists[p], send);
    send_counts[p] = (send.size() - before) / 8;  // in 8-byte words: every row is a multiple
    copies += static_cast<long>(lists[p].size());
  }
  return copies;
}

// Sends the packed rows (freeing `send`) and returns what the other ranks sent here.
// (Counts and offsets are 64-bit: Communicator::exchange_rows cuts what one call cannot hold.)
std::vector<char> Distribution::exchange_rows(std::vector<char>& send,
                                              const std::vector<std::size_t>& send_counts) const {
  // Rows go to the owner and the ranks near a tet: a neighbour-only exchange.
  const std::vector<std::int64_t> send_words(send_counts.begin(), send_counts.end());
  std::vector<std::int64_t> receive_words;
  std::vector<char> receive = comm_.exchange_rows_sparse(send.data(), send_words, 8, receive_words);
  send = std::vector<char>{};
  return receive;
}

// Sends every owned tet (with its rows) to its owner and to the ranks near it, and assembles what
// arrives into `out` (which may be `model` itself).
void Distribution::migrate(Model& model, TravellingState& state, Model& out,
                           TravellingState& out_state, const std::vector<StartJoint>* start_joints,
                           const std::vector<double>* start_reach) {
  const std::vector<std::vector<LocalIndex>> lists =
      destinations(model, false, start_reach, detection_positions(model, state));
  // Rows for the other ranks travel; this rank's own rows stay in `own` (no copy through MPI).
  std::vector<char> send;
  std::vector<std::vector<char>> own;
  std::vector<std::size_t> send_counts;
  release(cycle_traffic_);
  cycle_traffic_.sent_tets = pack_rows(model, state, lists, send, send_counts, &own, start_joints);
  move_rows(model, state, send, send_counts, own, out, out_state);
}

void Distribution::move_rows(Model& source, TravellingState& source_state, std::vector<char>& send,
                             const std::vector<std::size_t>& send_counts,
                             std::vector<std::vector<char>>& own, Model& out,
                             TravellingState& out_state) {
  cycle_traffic_.sent_bytes = static_cast<long>(send.size());
  // The rows hold everything that travels: the source arrays can go before the new ones come.
  source.nodes = NodeArrays{};
  source.tets = TetArrays{};
  source.joints = JointArrays{};
  release(source.tet_force_order);
  source_state = TravellingState{};
  std::vector<char> receive = exchange_rows(send, send_counts);
  std::vector<std::vector<char>*> buffers = {&receive};
  for (std::vector<char>& chunk : own) buffers.push_back(&chunk);
  assemble(buffers, out, out_state);
  build_exchange(out);
}

void Distribution::migrate_incremental(Model& model, TravellingState& state) {
  const int ranks = comm_.size(), me = comm_.rank();
  const std::vector<std::vector<LocalIndex>> lists =
      destinations(model, false, nullptr, detection_positions(model, state));
  const TetArrays& tets = model.tets;
  // The copies each owned tet needs now against those that exist: the new ones travel, the ones
  // no longer needed are dropped where they are.
  std::vector<std::pair<GlobalId, std::int32_t>> needed;
  std::vector<std::vector<LocalIndex>> sends(static_cast<std::size_t>(ranks));
  for (int p = 0; p < ranks; ++p) {
    if (p == me) continue;
    for (const LocalIndex t : lists[p]) {
      needed.emplace_back(tets.gid[t], p);
      if (!std::binary_search(held_by_.begin(), held_by_.end(), needed.back()))
        sends[p].push_back(t);
    }
  }
  std::sort(needed.begin(), needed.end());
  std::vector<std::vector<GlobalId>> drops(static_cast<std::size_t>(ranks));
  for (const auto& copy : held_by_)
    if (!std::binary_search(needed.begin(), needed.end(), copy))
      drops[copy.second].push_back(copy.first);
  held_by_ = std::move(needed);
  std::vector<GlobalId> dropped = comm_.exchange_sparse(drops);
  std::sort(dropped.begin(), dropped.end());

  // What stays here: the owned tets and every copy its owner did not drop; this rank's rows are
  // rebuilt in place (no copy through MPI).
  std::vector<LocalIndex>& kept = sends[me];
  kept.reserve(static_cast<std::size_t>(tets.size()));
  std::size_t found = 0;
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    const bool drop =
        !tets.is_owned(t) && std::binary_search(dropped.begin(), dropped.end(), tets.gid[t]);
    found += drop;
    if (!drop) kept.push_back(t);
  }
  FDEM_VERIFY(found == dropped.size(), "a rank drops only copies it holds");
  // A new copy carries every joint of its tet: the receiver may hold the other side already.
  std::vector<char> send;
  std::vector<std::vector<char>> own;
  std::vector<std::size_t> send_counts;
  release(cycle_traffic_);
  cycle_traffic_.dropped_tets = static_cast<long>(dropped.size());
  cycle_traffic_.sent_tets = pack_rows(model, state, sends, send, send_counts, &own, nullptr, true);
  move_rows(model, state, send, send_counts, own, model, state);
}

void Distribution::record_holders(const Model& model) {
  const TetArrays& tets = model.tets;
  std::vector<std::vector<GlobalId>> notices(static_cast<std::size_t>(comm_.size()));
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (!tets.is_owned(t)) notices[tet_owner_[t]].push_back(tets.gid[t]);
  std::vector<int> holder;
  const std::vector<GlobalId> held = comm_.exchange_sparse(notices, &holder);
  held_by_.clear();
  held_by_.reserve(held.size());
  for (std::size_t i = 0; i < held.size(); ++i) held_by_.emplace_back(held[i], holder[i]);
  std::sort(held_by_.begin(), held_by_.end());
}

void Distribution::assemble(const std::vector<std::vector<char>*>& buffers, Model& model,
                            TravellingState& state) {
  const int me = comm_.rank();
  ParsedRows parsed = parse_rows(buffers);
  std::vector<TetRow>& tet_rows = parsed.tets;
  std::vector<NodeRow>& node_rows = parsed.nodes;
  std::vector<JointRow>& joint_rows = parsed.joints;
  const auto by_gid = [](const auto& a, const auto& b) { return a.gid < b.gid; };
  const auto same_gid = [](const auto& a, const auto& b) { return a.gid == b.gid; };
  std::sort(tet_rows.begin(), tet_rows.end(), by_gid);
  FDEM_VERIFY(std::adjacent_find(tet_rows.begin(), tet_rows.end(), same_gid) == tet_rows.end(),
              "a tet arrives once");
  std::sort(node_rows.begin(), node_rows.end(), by_gid);
  node_rows.erase(std::unique(node_rows.begin(), node_rows.end(), same_gid), node_rows.end());
  // Owned nodes first (integrated here), then ghosts; each range in ascending gid.
  std::stable_partition(node_rows.begin(), node_rows.end(),
                        [&](const NodeRow& r) { return r.owner == me; });

  NodeArrays& nodes = model.nodes;
  const LocalIndex n_nodes = local_count(node_rows.size(), "nodes");
  nodes.resize(n_nodes);
  nodes.reference_positions.clear();  // every node is stored anew from its row
  nodes.n_owned = 0;
  node_owner_.resize(static_cast<std::size_t>(n_nodes));
  node_first_tet_.resize(static_cast<std::size_t>(n_nodes));
  for (const auto& field : travelling_node_fields) field.resize(state, std::size_t(n_nodes));
  for (LocalIndex n = 0; n < n_nodes; ++n) {
    const NodeRow& r = node_rows[n];
    if (r.owner == me) nodes.n_owned = n + 1;
    store_node_row(parsed, r, static_cast<std::size_t>(n), nodes, node_owner_, node_first_tet_,
                   state);
  }
  node_rows = std::vector<NodeRow>{};
  parsed.node_values = std::vector<unsigned char>{};
  nodes.compact_references();
  TetArrays& tets = model.tets;
  const LocalIndex n_tets = local_count(tet_rows.size(), "tetrahedra");
  tets.contact_group.resize(n_tets);  // every arriving tet has its group
  if (has_contact_faces_) tets.contact_faces.resize(2 * static_cast<std::size_t>(n_tets));
  tets.resize(n_tets);
  tets.n_owned = 0;
  tets.owned.assign(n_tets, 0);
  tets.active.assign(n_tets, 0);
  tet_owner_.resize(static_cast<std::size_t>(n_tets));
  state.tet_joint_state.assign(has_joint_state_ ? n_tets : 0, 0);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetRow& r = tet_rows[t];
    const bool touches_owned =
        store_tet_row(parsed, r, static_cast<std::size_t>(t), tets, tet_owner_, nodes, state);
    tets.owned[t] = r.owner == me;
    tets.active[t] = tets.owned[t] || touches_owned;
    tets.n_owned += tets.owned[t];
  }
  tet_rows = std::vector<TetRow>{};
  parsed.tet_values = std::vector<unsigned char>{};
  build_tet_force_order(tets, model.tet_force_order);

  // Joints whose two tets are both here (a joint with one tet missing is never computed here).
  std::sort(joint_rows.begin(), joint_rows.end(), by_gid);
  joint_rows.erase(std::unique(joint_rows.begin(), joint_rows.end(), same_gid), joint_rows.end());
  joint_rows.erase(std::remove_if(joint_rows.begin(), joint_rows.end(),
                                  [&](const JointRow& r) {
                                    return tets.find(r.tets[0]) < 0 || tets.find(r.tets[1]) < 0;
                                  }),
                   joint_rows.end());
  JointArrays& joints = model.joints;
  const LocalIndex n_joints = local_count(joint_rows.size(), "joints");
  joints = JointArrays{};
  joints.resize(n_joints);
  const std::size_t record_bytes = parsed.joint_record_bytes;
  state.joint_record_bytes = record_bytes;
  state.joint_records.assign(static_cast<std::size_t>(n_joints) * record_bytes, 0);
  for (LocalIndex j = 0; j < n_joints; ++j) {
    const JointRow& r = joint_rows[j];
    joints.gid[j] = r.gid;
    for (int i = 0; i < 6; ++i) {
      const LocalIndex n = nodes.find(r.nodes[i]);
      FDEM_VERIFY(n >= 0, "a joint's nodes are those of its tets");
      joints.nodes[6 * j + i] = n;
    }
    for (int i = 0; i < 2; ++i) joints.tets[2 * j + i] = tets.find(r.tets[i]);
    const unsigned char* record =
        store_joint_values(parsed, r, static_cast<std::size_t>(j), joints);
    std::copy_n(record, record_bytes,
                state.joint_records.data() + static_cast<std::size_t>(j) * record_bytes);
  }
  parsed.joint_values = std::vector<unsigned char>{};

  state.pairs = std::move(parsed.pairs);
  std::sort(state.pairs.begin(), state.pairs.end(), [](const PairRecord& p, const PairRecord& q) {
    return p.a != q.a ? p.a < q.a : p.b < q.b;
  });
  // Each pair came once, with the one copy of its tet a; kept where its tet b is held too.
  state.candidates = std::move(parsed.candidates);
  state.candidates.erase(std::remove_if(state.candidates.begin(), state.candidates.end(),
                                        [&](const GidPair& c) { return tets.find(c.b) < 0; }),
                         state.candidates.end());
  std::sort(state.candidates.begin(), state.candidates.end(),
            [](const GidPair& p, const GidPair& q) { return p.a != q.a ? p.a < q.a : p.b < q.b; });
}

}  // namespace fdem
