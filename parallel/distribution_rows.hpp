// The rows that carry tets, nodes, joints and the stages' pair records between ranks when the model
// is (re)distributed, and the packer that writes them (parallel/distribution*.cpp).  Internal to
// parallel/.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <numeric>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/fields.hpp"
#include "core/model.hpp"
#include "parallel/distribution.hpp"

namespace fdem::distribution_rows {

// Rows as they travel: each entry's identity and references as global ids, followed by the values
// of its fields that migrate (core/fields.hpp, in table order: the model's, then the stages'
// travelling ones), padded to whole 8-byte words.  Adding a field to a table adds it here.
struct TetRow {
  GlobalId gid;
  GlobalId nodes[4];
  std::int32_t owner;  // rank that owns it after this redistribution
  std::int32_t unused;
  std::int64_t values;  // sent: 0; parsed: its row in ParsedRows::tet_values
};
struct NodeRow {
  GlobalId gid;
  GlobalId first_tet;  // smallest tet gid that uses it (fixed)
  std::int32_t owner;  // the owner of first_tet after this redistribution
  std::int32_t unused;
  std::int64_t values;  // sent: 0; parsed: its row in ParsedRows::node_values
};
struct JointRow {
  GlobalId gid;
  GlobalId nodes[6];
  GlobalId tets[2];
  // Sent: 0; parsed: its row in ParsedRows::joint_values.  Its field values are followed by its
  // stage record (BlockHeader::joint_record_bytes) on the wire and in the parsed row.
  std::int64_t values;
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
// Bytes on the wire: padded to whole 8-byte words.
inline std::size_t padded(std::size_t bytes) {
  return (bytes + 7) / 8 * 8;
}
// Bytes of the migrating field values of one node, tet or joint.
inline std::size_t node_value_bytes() {
  static const std::size_t bytes = field_bytes(node_fields, FieldUse::migrates) +
                                   field_bytes(travelling_node_fields, FieldUse::migrates) +
                                   3 * sizeof(double);  // the reference position
  return bytes;
}
inline std::size_t tet_value_bytes() {
  static const std::size_t bytes = field_bytes(tet_fields, FieldUse::migrates) +
                                   field_bytes(travelling_tet_fields, FieldUse::migrates);
  return bytes;
}
inline std::size_t joint_value_bytes() {
  static const std::size_t bytes = field_bytes(joint_fields, FieldUse::migrates);
  return bytes;
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
    start_joint_.resize(1);
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
    const std::size_t joint_bytes = padded(joint_value_bytes() + record_bytes);
    out.reserve(out.size() + sizeof(header) +
                tet_list.size() * (sizeof(TetRow) + padded(tet_value_bytes())) +
                node_list.size() * (sizeof(NodeRow) + padded(node_value_bytes())) +
                (joint_list.size() + start_list.size()) * (sizeof(JointRow) + joint_bytes) +
                pair_list.size() * sizeof(PairRow) + candidate_list.size() * sizeof(GidPair));
    append(out, header);
    for (LocalIndex t : tet_list) {
      TetRow row{};
      row.gid = tets.gid[t];
      row.owner = tet_owner_[t];
      for (int c = 0; c < 4; ++c) row.nodes[c] = nodes.gid[tets.nodes[4 * t + c]];
      append(out, row);
      unsigned char* p = open_values(out, tet_value_bytes());
      p = pack_fields(tet_fields, FieldUse::migrates, tets, t, p);
      pack_fields(travelling_tet_fields, FieldUse::migrates, state_, t, p);
    }
    for (LocalIndex n : node_list) {
      NodeRow row{};
      row.gid = nodes.gid[n];
      row.first_tet = node_first_tet_[n];
      row.owner = node_owner_[n];
      append(out, row);
      unsigned char* p = open_values(out, node_value_bytes());
      p = pack_fields(node_fields, FieldUse::migrates, nodes, n, p);
      p = pack_fields(travelling_node_fields, FieldUse::migrates, state_, n, p);
      std::memcpy(p, nodes.x0(n).data(), 3 * sizeof(double));
    }
    for (LocalIndex j : joint_list) {
      JointRow row{};
      row.gid = joints.gid[j];
      for (int i = 0; i < 6; ++i) row.nodes[i] = nodes.gid[joints.nodes[6 * j + i]];
      for (int i = 0; i < 2; ++i) row.tets[i] = tets.gid[joints.tets[2 * j + i]];
      append(out, row);
      unsigned char* p = open_values(out, joint_value_bytes() + record_bytes);
      p = pack_fields(joint_fields, FieldUse::migrates, joints, j, p);
      if (record_bytes > 0)
        std::memcpy(p, state_.joint_records.data() + j * record_bytes, record_bytes);
    }
    for (const StartJoint* j : start_list) {  // intact, as JointArrays::resize leaves a joint
      JointRow row{};
      row.gid = j->gid;
      std::copy_n(j->nodes, 6, row.nodes);
      std::copy_n(j->tets, 2, row.tets);
      append(out, row);
      start_joint_.area0[0] = j->area0;
      start_joint_.law[0] = j->law;
      unsigned char* p = open_values(out, joint_value_bytes() + record_bytes);
      pack_fields(joint_fields, FieldUse::migrates, start_joint_, 0, p);
      // Its record stays zero: the stage makes its own at the start.
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
  JointArrays start_joint_;  // one intact joint: the values of a joint made at the start

  // Appends `bytes` zero bytes padded to whole words; returns where they start.
  static unsigned char* open_values(std::vector<char>& out, std::size_t bytes) {
    const std::size_t at = out.size();
    out.resize(at + padded(bytes), 0);
    return reinterpret_cast<unsigned char*>(out.data() + at);
  }
};

// The rows of packed buffers (each emptied once parsed), in the order they come, and their field
// values (row r's at values[r * value bytes]).
struct ParsedRows {
  std::vector<TetRow> tets;
  std::vector<NodeRow> nodes;
  std::vector<JointRow> joints;
  std::vector<unsigned char> tet_values, node_values;
  std::size_t joint_record_bytes = 0;
  std::vector<unsigned char> joint_values;  // joint_value_bytes() + joint_record_bytes per row
  std::vector<PairRow> pairs;
  std::vector<GidPair> candidates;

  const unsigned char* values_of(const TetRow& r) const {
    return tet_values.data() + static_cast<std::size_t>(r.values) * tet_value_bytes();
  }
  const unsigned char* values_of(const NodeRow& r) const {
    return node_values.data() + static_cast<std::size_t>(r.values) * node_value_bytes();
  }
  const unsigned char* values_of(const JointRow& r) const {
    return joint_values.data() +
           static_cast<std::size_t>(r.values) * (joint_value_bytes() + joint_record_bytes);
  }
};

// Writes node row `r` into entry n of the arrays and of the state's node fields (the fields that
// do not migrate, such as the force, are reset).  Its reference position is appended to the
// table: the caller compacts it once the rows are in (NodeArrays::compact_references).
inline void store_node_row(const ParsedRows& rows, const NodeRow& r, std::size_t n,
                           NodeArrays& nodes, std::vector<std::int32_t>& node_owner,
                           std::vector<GlobalId>& node_first_tet, TravellingState& state) {
  nodes.gid[n] = r.gid;
  node_owner[n] = r.owner;
  node_first_tet[n] = r.first_tet;
  const unsigned char* p =
      unpack_fields(node_fields, FieldUse::migrates, nodes, n, rows.values_of(r));
  p = unpack_fields(travelling_node_fields, FieldUse::migrates, state, n, p);
  double reference[3];
  std::memcpy(reference, p, sizeof reference);
  nodes.add_reference(static_cast<LocalIndex>(n), reference);
}

// Writes tet row `r` into entry t of the arrays and of the state's tet fields, its nodes found by
// gid in `nodes` (which must hold them); the roles (owned, active) are the caller's.  Returns
// whether it touches a node owned here.
inline bool store_tet_row(const ParsedRows& rows, const TetRow& r, std::size_t t, TetArrays& tets,
                          std::vector<std::int32_t>& tet_owner, const NodeArrays& nodes,
                          TravellingState& state) {
  tets.gid[t] = r.gid;
  tet_owner[t] = r.owner;
  bool touches_owned = false;
  for (std::size_t c = 0; c < 4; ++c) {
    const LocalIndex n = nodes.find(r.nodes[c]);
    FDEM_VERIFY(n >= 0, "a tet arrives with its nodes");
    tets.nodes[4 * t + c] = n;
    touches_owned = touches_owned || n < nodes.n_owned;
  }
  const unsigned char* p =
      unpack_fields(tet_fields, FieldUse::migrates, tets, t, rows.values_of(r));
  unpack_fields(travelling_tet_fields, FieldUse::migrates, state, t, p);
  return touches_owned;
}

// Writes joint row `r`'s field values into entry j and returns its stage record.
inline const unsigned char* store_joint_values(const ParsedRows& rows, const JointRow& r,
                                               std::size_t j, JointArrays& joints) {
  return unpack_fields(joint_fields, FieldUse::migrates, joints, j, rows.values_of(r));
}

inline ParsedRows parse_rows(const std::vector<std::vector<char>*>& buffers) {
  ParsedRows parsed;
  std::int64_t counts[5] = {0, 0, 0, 0, 0};
  const std::size_t tet_bytes = tet_value_bytes(), node_bytes = node_value_bytes();
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
      p += header.tets * (sizeof(TetRow) + padded(tet_bytes)) +
           header.nodes * (sizeof(NodeRow) + padded(node_bytes)) +
           header.joints * (sizeof(JointRow) + padded(joint_value_bytes() + record_bytes)) +
           header.pairs * sizeof(PairRow) + header.candidates * sizeof(GidPair);
    }
  const std::size_t joint_bytes = joint_value_bytes() + parsed.joint_record_bytes;
  const auto count = [&](int k) { return static_cast<std::size_t>(counts[k]); };
  parsed.tets.reserve(count(0));
  parsed.tet_values.reserve(count(0) * tet_bytes);
  parsed.nodes.reserve(count(1));
  parsed.node_values.reserve(count(1) * node_bytes);
  parsed.joints.reserve(count(2));
  parsed.joint_values.reserve(count(2) * joint_bytes);
  parsed.pairs.reserve(count(3));
  parsed.candidates.reserve(count(4));
  // Row `row` and its values (`bytes`, padded on the wire) into `keys` and `values`.
  const auto take_row = [](const char*& p, auto& keys, std::vector<unsigned char>& values,
                           std::size_t bytes) {
    auto row = take<typename std::decay_t<decltype(keys)>::value_type>(p);
    row.values = static_cast<std::int64_t>(keys.size());
    keys.push_back(row);
    values.insert(values.end(), p, p + bytes);
    p += padded(bytes);
  };
  for (std::vector<char>* rows : buffers) {
    for (const char* p = rows->data(); p < rows->data() + rows->size();) {
      const BlockHeader header = take<BlockHeader>(p);
      for (std::int64_t i = 0; i < header.tets; ++i)
        take_row(p, parsed.tets, parsed.tet_values, tet_bytes);
      for (std::int64_t i = 0; i < header.nodes; ++i)
        take_row(p, parsed.nodes, parsed.node_values, node_bytes);
      for (std::int64_t i = 0; i < header.joints; ++i)
        take_row(p, parsed.joints, parsed.joint_values, joint_bytes);
      for (std::int64_t i = 0; i < header.pairs; ++i) parsed.pairs.push_back(take<PairRow>(p));
      for (std::int64_t i = 0; i < header.candidates; ++i)
        parsed.candidates.push_back(take<GidPair>(p));
    }
    *rows = std::vector<char>{};  // parsed: its memory goes back before the arrays are built
  }
  return parsed;
}

}  // namespace fdem::distribution_rows
