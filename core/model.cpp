#include "core/model.hpp"

#include <algorithm>
#include <numeric>
#include <string>

#include "core/error.hpp"

namespace fdem {

LocalIndex local_count(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(max_local_entries))
    throw InputError("one rank would hold " + std::to_string(n) + " " + what + ", more than the " +
                     std::to_string(max_local_entries) +
                     " one rank can index (32-bit local indices): run on more ranks");
  return static_cast<LocalIndex>(n);
}

void NodeArrays::resize(LocalIndex n) {
  gid.resize(n);
  x.resize(3 * n);
  x0.resize(3 * n);
  v.resize(3 * n);
  f.resize(3 * n);
  mass.resize(n);
  piece.resize(n);
  constrained.resize(n);
  prescribed_velocity.resize(3 * n);
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
  gid.resize(n);
  nodes.resize(4 * n);
  dm_inv.resize(9 * n);
  volume0.resize(n);
  material.resize(n);
  piece.resize(n);
  viscosity.resize(n);
}

void JointArrays::resize(LocalIndex n) {
  gid.resize(n);
  nodes.resize(6 * n);
  tets.resize(2 * n);
  area0.resize(n);
  law.resize(n);
  broken.resize(n, 0);
  mode.resize(n, 0);
  failure_time.resize(n, -1.0);
  damage.resize(n, 0.0);
}

std::int32_t count_fragments(const Model& model) {
  // Without joints the pieces at t = 0 are the connected components, and they stay so.
  if (model.joints.size() == 0) return static_cast<std::int32_t>(model.pieces.size());
  // Union-find over nodes: a tet links its four nodes; an intact joint links its two tets.
  const LocalIndex n_nodes = model.nodes.size();
  std::vector<LocalIndex> parent(n_nodes);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](LocalIndex i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto unite = [&](LocalIndex a, LocalIndex b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  const TetArrays& tets = model.tets;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 1; c < 4; ++c) unite(tets.nodes[4 * t], tets.nodes[4 * t + c]);
  const JointArrays& joints = model.joints;
  for (LocalIndex j = 0; j < joints.size(); ++j)
    if (!joints.broken[j]) unite(joints.nodes[6 * j], joints.nodes[6 * j + 3]);
  std::vector<char> is_root(n_nodes, 0);
  for (LocalIndex t = 0; t < tets.size(); ++t) is_root[find(tets.nodes[4 * t])] = 1;
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
