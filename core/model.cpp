#include "core/model.hpp"

#include <algorithm>
#include <numeric>

namespace fdem {

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

void TetArrays::resize(LocalIndex n) {
  gid.resize(n);
  nodes.resize(4 * n);
  dm_inv.resize(9 * n);
  volume0.resize(n);
  material.resize(n);
  piece.resize(n);
  viscosity.resize(n);
}

void build_node_corner_map(const TetArrays& tets, LocalIndex n_nodes, NodeCornerMap& map) {
  const LocalIndex n_tets = tets.size();
  map.offsets.assign(n_nodes + 1, 0);
  for (LocalIndex s = 0; s < 4 * n_tets; ++s) ++map.offsets[tets.nodes[s] + 1];
  std::partial_sum(map.offsets.begin(), map.offsets.end(), map.offsets.begin());
  // Visit tets in ascending global id so each row comes out sorted by gid.
  std::vector<LocalIndex> order(n_tets);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](LocalIndex a, LocalIndex b) { return tets.gid[a] < tets.gid[b]; });
  std::vector<LocalIndex> fill(map.offsets.begin(), map.offsets.end() - 1);
  map.slots.resize(4 * n_tets);
  for (LocalIndex t : order)
    for (int c = 0; c < 4; ++c) map.slots[fill[tets.nodes[4 * t + c]]++] = 4 * t + c;
}

}  // namespace fdem
