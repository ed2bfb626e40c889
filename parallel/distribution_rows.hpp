// The rows that carry tets, nodes, joints and the stages' pair records between ranks when the model
// is (re)distributed, and the packer that writes them (parallel/distribution*.cpp).  Internal to
// parallel/.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <numeric>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/model.hpp"
#include "parallel/distribution.hpp"

namespace fdem::distribution_rows {

// Rows as they travel: plain values, node and tet references as global ids.
struct TetRow {
  GlobalId gid;
  std::int32_t owner;  // rank that owns it after this redistribution
  GlobalId nodes[4];
  double dm_inv[9];
  double volume0, viscosity;
  std::int32_t material, piece, contact_group;
  std::uint8_t joint_state;
};
struct NodeRow {
  GlobalId gid;
  GlobalId first_tet;  // smallest tet gid that uses it (fixed)
  std::int32_t owner;  // the owner of first_tet after this redistribution
  double x[3], x0[3], v[3], prescribed_velocity[3], x_at_detection[3];
  double mass;
  std::int32_t piece;
  std::uint8_t constrained;
};
struct JointRow {
  GlobalId gid;
  GlobalId nodes[6];
  GlobalId tets[2];
  double area0, failure_time, damage;
  std::int32_t law;
  std::uint8_t broken, mode;
  // Where its stage record is: sent, 0; parsed, its index in ParsedRows::joint_records.  The
  // record itself follows the row (BlockHeader::joint_record_bytes, padded to 8 bytes).
  std::int64_t record;
};
using PairRow = PairRecord;  // stage state of a pair of tets, sent with its first tet
struct BlockHeader {
  std::int64_t tets = 0, nodes = 0, joints = 0, pairs = 0, candidates = 0;
  std::int64_t joint_record_bytes = 0;  // of each joint's stage record (0: none)
};
static_assert(sizeof(TetRow) % 8 == 0 && sizeof(NodeRow) % 8 == 0 && sizeof(JointRow) % 8 == 0 &&
                  sizeof(PairRow) % 8 == 0 && sizeof(GidPair) % 8 == 0 &&
                  sizeof(BlockHeader) % 8 == 0,
              "rows travel as 8-byte words");
// A joint record's bytes on the wire: padded to whole 8-byte words.
inline std::size_t padded_record_bytes(std::size_t bytes) {
  return (bytes + 7) / 8 * 8;
}

template <class T>
inline void append(std::vector<char>& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  const std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

template <class T>
inline T take(const char*& p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  p += sizeof(T);
  return value;
}

// Packs the rows that travel with a set of tets: the tets, their nodes (once per block), the
// joints whose first tet they are, and the stages' records of their pairs and the contact
// candidates (both keyed by their first tet).
class RowPacker {
 public:
  // `tet_owner`, `node_owner`, `node_first_tet`: per local tet and node, their owners after the
  // redistribution and the nodes' first tets.
  // `start_joints` (distributed start, model.joints empty): the joints whose tet A is local, by
  // gid, with global references.
  // `both_sides`: a tet carries every joint it is a side of (incremental migration: a rank that
  // already holds one side gets the joint with the other), not only those whose tet A it is.
  RowPacker(const Model& model, const TravellingState& state,
            const std::vector<std::int32_t>& tet_owner, const std::vector<std::int32_t>& node_owner,
            const std::vector<GlobalId>& node_first_tet,
            const std::vector<StartJoint>* start_joints = nullptr, bool both_sides = false)
      : model_(model),
        state_(state),
        tet_owner_(tet_owner),
        node_owner_(node_owner),
        node_first_tet_(node_first_tet),
        start_joints_(start_joints),
        stamp_(model.nodes.size(), -1),
        joint_stamp_(model.joints.size(), -1) {
    const JointArrays& joints = model.joints;
    const int sides = both_sides ? 2 : 1;
    joint_offsets_.assign(static_cast<std::size_t>(model.tets.size()) + 1, 0);
    for (LocalIndex j = 0; j < joints.size(); ++j)
      for (int s = 0; s < sides; ++s) ++joint_offsets_[joints.tets[2 * j + s] + 1];
    std::partial_sum(joint_offsets_.begin(), joint_offsets_.end(), joint_offsets_.begin());
    joint_list_.resize(static_cast<std::size_t>(joint_offsets_.back()));
    std::vector<std::int64_t> fill(joint_offsets_.begin(), joint_offsets_.end() - 1);
    for (LocalIndex j = 0; j < joints.size(); ++j)
      for (int s = 0; s < sides; ++s) joint_list_[fill[joints.tets[2 * j + s]]++] = j;
  }

  void pack(const std::vector<LocalIndex>& tet_list, std::vector<char>& out) {
    ++mark_;
    const NodeArrays& nodes = model_.nodes;
    const TetArrays& tets = model_.tets;
    const JointArrays& joints = model_.joints;
    std::vector<LocalIndex> node_list, joint_list;
    std::vector<const StartJoint*> start_list;
    std::vector<const PairRecord*> pair_list;
    std::vector<GidPair> candidate_list;
    for (LocalIndex t : tet_list) {
      if (start_joints_) {
        auto it =
            std::lower_bound(start_joints_->begin(), start_joints_->end(), tets.gid[t],
                             [](const StartJoint& j, GlobalId value) { return j.tets[0] < value; });
        for (; it != start_joints_->end() && it->tets[0] == tets.gid[t]; ++it)
          start_list.push_back(&*it);
      }
      for (int c = 0; c < 4; ++c) {
        const LocalIndex n = tets.nodes[4 * static_cast<std::size_t>(t) + c];
        if (stamp_[n] != mark_) {
          stamp_[n] = mark_;
          node_list.push_back(n);
        }
      }
      for (std::int64_t k = joint_offsets_[t]; k < joint_offsets_[t + 1]; ++k) {
        const LocalIndex j = joint_list_[k];
        if (joint_stamp_[j] != mark_) {  // once per block, though both its tets may be listed
          joint_stamp_[j] = mark_;
          joint_list.push_back(j);
        }
      }
      const GlobalId g = tets.gid[t];
      auto it = std::lower_bound(state_.pairs.begin(), state_.pairs.end(), g,
                                 [](const PairRecord& e, GlobalId value) { return e.a < value; });
      for (; it != state_.pairs.end() && it->a == g; ++it) pair_list.push_back(&*it);
      auto c = std::lower_bound(state_.candidates.begin(), state_.candidates.end(), g,
                                [](const GidPair& e, GlobalId value) { return e.a < value; });
      for (; c != state_.candidates.end() && c->a == g; ++c) candidate_list.push_back(*c);
    }
    BlockHeader header;
    header.tets = static_cast<std::int64_t>(tet_list.size());
    header.nodes = static_cast<std::int64_t>(node_list.size());
    header.joints = static_cast<std::int64_t>(joint_list.size() + start_list.size());
    header.pairs = static_cast<std::int64_t>(pair_list.size());
    header.candidates = static_cast<std::int64_t>(candidate_list.size());
    const std::size_t record_bytes = state_.joint_record_bytes;
    header.joint_record_bytes = static_cast<std::int64_t>(record_bytes);
    out.reserve(out.size() + sizeof(header) + tet_list.size() * sizeof(TetRow) +
                node_list.size() * sizeof(NodeRow) +
                (joint_list.size() + start_list.size()) *
                    (sizeof(JointRow) + padded_record_bytes(record_bytes)) +
                pair_list.size() * sizeof(PairRow) + candidate_list.size() * sizeof(GidPair));
    append(out, header);
    for (LocalIndex t : tet_list) {
      TetRow row{};
      row.gid = tets.gid[t];
      row.owner = tet_owner_[t];
      for (int c = 0; c < 4; ++c) row.nodes[c] = nodes.gid[tets.nodes[4 * t + c]];
      std::copy_n(&tets.dm_inv[9 * static_cast<std::size_t>(t)], 9, row.dm_inv);
      row.volume0 = tets.volume0[t];
      row.viscosity = tets.viscosity[t];
      row.material = tets.material[t];
      row.piece = tets.piece[t];
      row.contact_group = tets.group_of(t);
      row.joint_state = state_.tet_joint_state.empty() ? 0 : state_.tet_joint_state[t];
      append(out, row);
    }
    for (LocalIndex n : node_list) {
      NodeRow row{};
      row.gid = nodes.gid[n];
      row.first_tet = node_first_tet_[n];
      row.owner = node_owner_[n];
      for (int k = 0; k < 3; ++k) {
        row.x[k] = nodes.x[3 * n + k];
        row.x0[k] = nodes.x0[3 * n + k];
        row.v[k] = nodes.v[3 * n + k];
        row.prescribed_velocity[k] = nodes.prescribed_velocity[3 * n + k];
        row.x_at_detection[k] = state_.x_at_detection[3 * n + k];
      }
      row.mass = nodes.mass[n];
      row.piece = nodes.piece[n];
      row.constrained = nodes.constrained[n];
      append(out, row);
    }
    for (LocalIndex j : joint_list) {
      JointRow row{};
      row.gid = joints.gid[j];
      for (int i = 0; i < 6; ++i) row.nodes[i] = nodes.gid[joints.nodes[6 * j + i]];
      for (int i = 0; i < 2; ++i) row.tets[i] = tets.gid[joints.tets[2 * j + i]];
      row.area0 = joints.area0[j];
      row.failure_time = joints.failure_time[j];
      row.damage = joints.damage[j];
      row.law = joints.law[j];
      row.broken = joints.broken[j];
      row.mode = joints.mode[j];
      append(out, row);
      append_record(out, state_.joint_records.data() + j * record_bytes, record_bytes);
    }
    for (const StartJoint* j : start_list) {  // intact, as JointArrays::resize leaves a joint
      JointRow row{};
      row.gid = j->gid;
      std::copy_n(j->nodes, 6, row.nodes);
      std::copy_n(j->tets, 2, row.tets);
      row.area0 = j->area0;
      row.failure_time = -1.0;
      row.damage = 0.0;
      row.law = j->law;
      row.broken = 0;
      row.mode = 0;
      append(out, row);
      append_record(out, nullptr, record_bytes);  // made at the start: the stage makes its own
    }
    for (const PairRecord* e : pair_list) append(out, *e);
    for (const GidPair& c : candidate_list) append(out, c);
  }

 private:
  const Model& model_;
  const TravellingState& state_;
  const std::vector<std::int32_t>& tet_owner_;
  const std::vector<std::int32_t>& node_owner_;
  const std::vector<GlobalId>& node_first_tet_;
  const std::vector<StartJoint>* start_joints_;
  std::vector<int> stamp_, joint_stamp_;
  int mark_ = 0;
  std::vector<std::int64_t> joint_offsets_;
  std::vector<LocalIndex> joint_list_;

  // `bytes` of `record` (zeros when null), padded to whole words.
  static void append_record(std::vector<char>& out, const std::uint8_t* record, std::size_t bytes) {
    const std::size_t at = out.size();
    out.resize(at + padded_record_bytes(bytes), 0);
    if (record && bytes > 0) std::memcpy(out.data() + at, record, bytes);
  }
};

// Writes node row `r` into entry n of the arrays (its force zeroed).
inline void store_node_row(const NodeRow& r, std::size_t n, NodeArrays& nodes,
                           std::vector<std::int32_t>& node_owner,
                           std::vector<GlobalId>& node_first_tet,
                           std::vector<double>& x_at_detection) {
  nodes.gid[n] = r.gid;
  node_owner[n] = r.owner;
  node_first_tet[n] = r.first_tet;
  for (std::size_t k = 0; k < 3; ++k) {
    nodes.x[3 * n + k] = r.x[k];
    nodes.x0[3 * n + k] = r.x0[k];
    nodes.v[3 * n + k] = r.v[k];
    nodes.f[3 * n + k] = 0.0;
    nodes.prescribed_velocity[3 * n + k] = r.prescribed_velocity[k];
    x_at_detection[3 * n + k] = r.x_at_detection[k];
  }
  nodes.mass[n] = r.mass;
  nodes.piece[n] = r.piece;
  nodes.constrained[n] = r.constrained;
}

// Writes tet row `r` into entry t of the arrays, its nodes found by gid in `nodes` (which must
// hold them); the roles (owned, active) are the caller's.  Returns whether it touches a node
// owned here.
inline bool store_tet_row(const TetRow& r, std::size_t t, TetArrays& tets,
                          std::vector<std::int32_t>& tet_owner, const NodeArrays& nodes) {
  tets.gid[t] = r.gid;
  tet_owner[t] = r.owner;
  bool touches_owned = false;
  for (std::size_t c = 0; c < 4; ++c) {
    const LocalIndex n = nodes.find(r.nodes[c]);
    FDEM_VERIFY(n >= 0, "a tet arrives with its nodes");
    tets.nodes[4 * t + c] = n;
    touches_owned = touches_owned || n < nodes.n_owned;
  }
  std::copy_n(r.dm_inv, 9, &tets.dm_inv[9 * t]);
  tets.volume0[t] = r.volume0;
  tets.viscosity[t] = r.viscosity;
  tets.material[t] = r.material;
  tets.piece[t] = r.piece;
  tets.contact_group[t] = r.contact_group;
  return touches_owned;
}

// The rows of packed buffers (each emptied once parsed), in the order they come.
struct ParsedRows {
  std::vector<TetRow> tets;
  std::vector<NodeRow> nodes;
  std::vector<JointRow> joints;  // JointRow::record: the index of its record
  std::size_t joint_record_bytes = 0;
  std::vector<std::uint8_t> joint_records;  // joint_record_bytes per joint row, in row order
  std::vector<PairRow> pairs;
  std::vector<GidPair> candidates;
};
inline ParsedRows parse_rows(std::initializer_list<std::vector<char>*> buffers) {
  ParsedRows parsed;
  std::int64_t counts[5] = {0, 0, 0, 0, 0};
  // Exact sizes first: growing the row arrays would hold up to three copies at once.
  for (std::vector<char>* rows : buffers)
    for (const char* p = rows->data(); p < rows->data() + rows->size();) {
      const BlockHeader header = take<BlockHeader>(p);
      counts[0] += header.tets;
      counts[1] += header.nodes;
      counts[2] += header.joints;
      counts[3] += header.pairs;
      counts[4] += header.candidates;
      const auto record_bytes = static_cast<std::size_t>(header.joint_record_bytes);
      if (header.joints > 0) {
        FDEM_VERIFY(parsed.joint_record_bytes == 0 || parsed.joint_record_bytes == record_bytes,
                    "every rank sends joint records of one size");
        parsed.joint_record_bytes = record_bytes;
      }
      p += header.tets * sizeof(TetRow) + header.nodes * sizeof(NodeRow) +
           header.joints * (sizeof(JointRow) + padded_record_bytes(record_bytes)) +
           header.pairs * sizeof(PairRow) + header.candidates * sizeof(GidPair);
    }
  parsed.tets.reserve(static_cast<std::size_t>(counts[0]));
  parsed.nodes.reserve(static_cast<std::size_t>(counts[1]));
  parsed.joints.reserve(static_cast<std::size_t>(counts[2]));
  parsed.joint_records.reserve(static_cast<std::size_t>(counts[2]) * parsed.joint_record_bytes);
  parsed.pairs.reserve(static_cast<std::size_t>(counts[3]));
  parsed.candidates.reserve(static_cast<std::size_t>(counts[4]));
  for (std::vector<char>* rows : buffers) {
    for (const char* p = rows->data(); p < rows->data() + rows->size();) {
      const BlockHeader header = take<BlockHeader>(p);
      for (std::int64_t i = 0; i < header.tets; ++i) parsed.tets.push_back(take<TetRow>(p));
      for (std::int64_t i = 0; i < header.nodes; ++i) parsed.nodes.push_back(take<NodeRow>(p));
      const auto record_bytes = static_cast<std::size_t>(header.joint_record_bytes);
      for (std::int64_t i = 0; i < header.joints; ++i) {
        JointRow row = take<JointRow>(p);
        row.record = static_cast<std::int64_t>(parsed.joints.size());
        parsed.joints.push_back(row);
        parsed.joint_records.insert(parsed.joint_records.end(), p, p + record_bytes);
        p += padded_record_bytes(record_bytes);
      }
      for (std::int64_t i = 0; i < header.pairs; ++i) parsed.pairs.push_back(take<PairRow>(p));
      for (std::int64_t i = 0; i < header.candidates; ++i)
        parsed.candidates.push_back(take<GidPair>(p));
    }
    *rows = std::vector<char>{};  // parsed: its memory goes back before the arrays are built
  }
  return parsed;
}

}  // namespace fdem::distribution_rows
