#include "core/model.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>

#include "core/error.hpp"
#include "core/fields.hpp"

namespace fdem {

LocalIndex local_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(max_local_entries))
    throw InputError("one rank would hold " + std::to_string(n) + " " + what + ", more than the " +
                     std::to_string(max_local_entries) +
                     " one rank can index (32-bit local indices): run on more ranks");
  return static_cast<LocalIndex>(n);
}

// A member added to one of the array structs without a line in its field table
// (core/fields.hpp) fails here: the structs hold their identity and roles and the tables' arrays.
namespace {
using AnyArray = std::vector<double>;
struct NodeArraysShape {
  LocalIndex n_owned;
  bool has_prescribed_velocity;
  std::vector<GlobalId> gid;
  AnyArray fields[std::tuple_size_v<decltype(node_fields)>];
  std::vector<double> reference_positions;
};
struct TetArraysShape {
  LocalIndex n_owned;
  std::vector<GlobalId> gid;
  std::vector<LocalIndex> nodes;
  AnyArray fields[std::tuple_size_v<decltype(tet_fields)>];
  std::vector<std::uint8_t> enclosed, owned, active;
};
struct JointArraysShape {
  std::vector<GlobalId> gid;
  std::vector<LocalIndex> nodes, tets;
  AnyArray fields[std::tuple_size_v<decltype(joint_fields)>];
};
static_assert(sizeof(NodeArrays) == sizeof(NodeArraysShape), "node field without a table line");
static_assert(sizeof(TetArrays) == sizeof(TetArraysShape), "tet field without a table line");
static_assert(sizeof(JointArrays) == sizeof(JointArraysShape), "joint field without a table line");
}  // namespace

void NodeArrays::resize(LocalIndex n) {
  resize_exact(gid, static_cast<std::size_t>(n));
  if (has_prescribed_velocity)
    resize_exact(prescribed_velocity, 3 * static_cast<std::size_t>(n), 0.0);
  else
    release(prescribed_velocity);
  for (const auto& field : node_fields) field.resize(*this, static_cast<std::size_t>(n));
}

void NodeArrays::add_reference(LocalIndex n, const double* position) {
  FDEM_VERIFY(reference_positions.size() / 3 <
                  static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()),
              "reference positions fit 32-bit indices");
  reference[static_cast<std::size_t>(n)] =
      static_cast<std::int32_t>(reference_positions.size() / 3);
  reference_positions.insert(reference_positions.end(), position, position + 3);
}

void NodeArrays::compact_references() {
  // Equal positions by their bits (a position is a value here, so +0 and -0 stay apart).
  struct Bits {
    std::uint64_t w[3];
    bool operator==(const Bits& o) const {
      return w[0] == o.w[0] && w[1] == o.w[1] && w[2] == o.w[2];
    }
  };
  struct Hash {
    std::size_t operator()(const Bits& b) const {
      std::uint64_t h = 0xcbf29ce484222325ULL;
      for (std::uint64_t w : b.w) h = (h ^ w) * 0x100000001b3ULL;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  std::unordered_map<Bits, std::int32_t, Hash> index;
  std::vector<double> kept;
  for (std::int32_t& r : reference) {
    Bits b;
    std::memcpy(b.w, reference_positions.data() + 3 * static_cast<std::size_t>(r), sizeof b.w);
    const auto [it, added] = index.emplace(b, static_cast<std::int32_t>(kept.size() / 3));
    if (added)
      kept.insert(kept.end(), reference_positions.data() + 3 * static_cast<std::size_t>(r),
                  reference_positions.data() + 3 * static_cast<std::size_t>(r) + 3);
    r = it->second;
  }
  kept.shrink_to_fit();
  reference_positions = std::move(kept);
}

LocalIndex NodeArrays::find(GlobalId id) const {
  const auto owned_end = gid.begin() + n_owned;
  auto it = std::lower_bound(gid.begin(), owned_end, id);
  if (it == owned_end || *it != id) it = std::lower_bound(owned_end, gid.end(), id);
  return it != gid.end() && *it == id ? static_cast<LocalIndex>(it - gid.begin()) : LocalIndex{-1};
}

LocalIndex TetArrays::find(GlobalId id) const {
  const auto it = std::lower_bound(gid.begin(), gid.end(), id);
  return it != gid.end() && *it == id ? static_cast<LocalIndex>(it - gid.begin()) : LocalIndex{-1};
}

void TetArrays::resize(LocalIndex n) {
  resize_exact(gid, static_cast<std::size_t>(n));
  resize_exact(nodes, static_cast<std::size_t>(4 * n));
  for (const auto& field : tet_fields) field.resize(*this, static_cast<std::size_t>(n));
}

void JointArrays::resize(LocalIndex n) {
  resize_exact(gid, static_cast<std::size_t>(n));
  resize_exact(nodes, static_cast<std::size_t>(6 * n));
  resize_exact(tets, static_cast<std::size_t>(2 * n));
  for (const auto& field : joint_fields) field.resize(*this, static_cast<std::size_t>(n));
}

void PieceTable::add_body(std::int32_t pieces) {
  FDEM_VERIFY(pieces >= 0 && first_.back() <= std::numeric_limits<std::int32_t>::max() - pieces,
              "piece ids fit 32 bits");
  first_.push_back(first_.back() + pieces);
}

std::int32_t PieceTable::body_of(std::int32_t piece) const {
  FDEM_VERIFY(piece >= 0 && piece < first_.back(), "a piece id of the model");
  return static_cast<std::int32_t>(std::upper_bound(first_.begin(), first_.end(), piece) -
                                   first_.begin()) -
         1;
}

std::int32_t PieceTable::slot(std::int32_t piece) const {
  if (kept_id_.empty()) return -1;
  // Kept ids are often one dense range (one process, a directory block): no search then.
  const std::int64_t offset = std::int64_t{piece} - kept_id_.front();
  if (kept_id_.back() - kept_id_.front() + 1 == static_cast<std::int64_t>(kept_id_.size()))
    return offset >= 0 && offset < static_cast<std::int64_t>(kept_id_.size())
               ? static_cast<std::int32_t>(offset)
               : -1;
  const auto it = std::lower_bound(kept_id_.begin(), kept_id_.end(), piece);
  return it != kept_id_.end() && *it == piece ? static_cast<std::int32_t>(it - kept_id_.begin())
                                              : -1;
}

void PieceTable::keep_range(std::int32_t begin, std::int32_t end) {
  std::vector<std::int32_t> ids(static_cast<std::size_t>(std::max(0, end - begin)));
  std::iota(ids.begin(), ids.end(), begin);
  keep(ids);
}

void PieceTable::keep(const std::vector<std::int32_t>& sorted_ids) {
  std::vector<std::int32_t> ids;
  std::vector<PieceInfo> infos;
  ids.reserve(kept_id_.size() + sorted_ids.size());
  infos.reserve(ids.capacity());
  std::size_t i = 0, j = 0;
  while (i < kept_id_.size() || j < sorted_ids.size()) {
    if (j == sorted_ids.size() || (i < kept_id_.size() && kept_id_[i] <= sorted_ids[j])) {
      if (j < sorted_ids.size() && kept_id_[i] == sorted_ids[j]) ++j;
      ids.push_back(kept_id_[i]);
      infos.push_back(kept_[i++]);
      continue;
    }
    const std::int32_t id = sorted_ids[j++];
    if (!ids.empty() && ids.back() == id) continue;
    PieceInfo info;
    info.body = body_of(id);
    info.index_in_body = id - first_[info.body];
    ids.push_back(id);
    infos.push_back(info);
  }
  kept_id_ = std::move(ids);
  kept_ = std::move(infos);
}

void PieceTable::keep_only_range(std::int32_t begin, std::int32_t end) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < kept_id_.size(); ++i)
    if (kept_id_[i] >= begin && kept_id_[i] < end) {
      kept_id_[out] = kept_id_[i];
      kept_[out++] = kept_[i];
    }
  kept_id_.resize(out);
  kept_.resize(out);
  kept_id_.shrink_to_fit();
  kept_.shrink_to_fit();
}

PieceInfo& PieceTable::operator[](std::int32_t piece) {
  const std::int32_t s = slot(piece);
  FDEM_VERIFY(s >= 0, "the piece is kept here");
  return kept_[static_cast<std::size_t>(s)];
}

const PieceInfo& PieceTable::operator[](std::int32_t piece) const {
  const std::int32_t s = slot(piece);
  FDEM_VERIFY(s >= 0, "the piece is kept here");
  return kept_[static_cast<std::size_t>(s)];
}

namespace {

// Union-find over n entries, the smaller index the root.
struct UnionFind {
  std::vector<LocalIndex> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  LocalIndex find(LocalIndex i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(LocalIndex a, LocalIndex b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

bool contact_possible(const Model& model) {
  std::int64_t free_pieces = 0;
  for (std::int32_t b = 0; b < model.pieces.bodies(); ++b)
    free_pieces += model.body_fixed[b] ? 0 : model.pieces.pieces_in_body(b);
  const bool grouped =
      !model.tets.contact_group.empty() &&
      *std::max_element(model.tets.contact_group.begin(), model.tets.contact_group.end()) >= 1;
  return (model.pieces.size() >= 2 || grouped) && free_pieces >= 1;
}

std::int32_t count_fragments(const Model& model) {
  // Without joints the pieces at t = 0 are the connected components, and they stay so.
  if (model.joints.size() == 0) return static_cast<std::int32_t>(model.pieces.size());
  const JointArrays& joints = model.joints;
  const TetArrays& tets = model.tets;
  // While no joint has broken, the pieces linked by joints (interface joints join bodies): a
  // union-find over pieces, not over nodes (5 B per node was the end of a large run's peak).
  if (std::find(joints.broken.begin(), joints.broken.end(), 1) == joints.broken.end()) {
    UnionFind pieces(model.pieces.size());
    for (LocalIndex j = 0; j < joints.size(); ++j)
      pieces.unite(tets.piece[joints.tets[2 * j]], tets.piece[joints.tets[2 * j + 1]]);
    std::int32_t roots = 0;
    for (std::size_t p = 0; p < model.pieces.size(); ++p)
      roots += pieces.find(static_cast<LocalIndex>(p)) == static_cast<LocalIndex>(p) ? 1 : 0;
    return roots;
  }
  // Union-find over nodes: a tet links its four nodes; an intact joint links its two tets.
  UnionFind nodes(static_cast<std::size_t>(model.nodes.size()));
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 1; c < 4; ++c) nodes.unite(tets.nodes[4 * t], tets.nodes[4 * t + c]);
  for (LocalIndex j = 0; j < joints.size(); ++j)
    if (!joints.broken[j]) nodes.unite(joints.nodes[6 * j], joints.nodes[6 * j + 3]);
  std::vector<char> is_root(static_cast<std::size_t>(model.nodes.size()), 0);
  for (LocalIndex t = 0; t < tets.size(); ++t) is_root[nodes.find(tets.nodes[4 * t])] = 1;
  return static_cast<std::int32_t>(std::count(is_root.begin(), is_root.end(), 1));
}

void build_tet_force_order(const TetArrays& tets, std::vector<LocalIndex>& order) {
  order.clear();
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_active(t)) order.push_back(t);
  std::sort(order.begin(), order.end(),
            [&](LocalIndex a, LocalIndex b) { return tets.gid[a] < tets.gid[b]; });
}

}  // namespace fdem
