#include "parallel/partition.hpp"

#include <metis.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include "core/error.hpp"

namespace fdem {

namespace {

// Tets in ascending global id (the model's force order when it is current).
std::vector<LocalIndex> tets_by_gid(const Model& model) {
  if (model.tet_force_order.size() == model.tets.gid.size()) return model.tet_force_order;
  std::vector<LocalIndex> order;
  build_tet_force_order(model.tets, order);
  return order;
}

// Pairs (vertex, vertex) of tets sharing a triangle.
void face_pairs(const TetArrays& tets, const std::vector<std::int32_t>& vertex_of_tet,
                std::vector<std::pair<std::int32_t, std::int32_t>>& pairs) {
  struct Face {
    std::array<LocalIndex, 3> n;
    std::int32_t vertex;
  };
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  std::vector<Face> faces;
  faces.reserve(4 * tets.gid.size());
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (const auto& f : kFace) {
      Face face{{tets.nodes[4 * t + f[0]], tets.nodes[4 * t + f[1]], tets.nodes[4 * t + f[2]]},
                vertex_of_tet[t]};
      std::sort(face.n.begin(), face.n.end());
      faces.push_back(face);
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return a.n != b.n ? a.n < b.n : a.vertex < b.vertex;
  });
  for (std::size_t i = 0; i + 1 < faces.size(); ++i) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].n == faces[i].n) ++j;
    for (std::size_t a = i; a < j; ++a)  // ≥ 3 tets on one triangle: a non-manifold mesh; link all
      for (std::size_t b = a + 1; b < j; ++b) pairs.emplace_back(faces[a].vertex, faces[b].vertex);
    i = j - 1;
  }
}

// Pairs of tets sharing at least one node.
void node_pairs(const TetArrays& tets, const std::vector<std::int32_t>& vertex_of_tet,
                std::vector<std::pair<std::int32_t, std::int32_t>>& pairs) {
  LocalIndex n_nodes = 0;
  for (LocalIndex n : tets.nodes) n_nodes = std::max(n_nodes, n + 1);
  std::vector<std::int64_t> start(static_cast<std::size_t>(n_nodes) + 1, 0);
  for (LocalIndex n : tets.nodes) ++start[n + 1];
  for (LocalIndex n = 0; n < n_nodes; ++n) start[n + 1] += start[n];
  std::vector<std::int32_t> node_tets(tets.nodes.size());
  std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c) node_tets[fill[tets.nodes[4 * t + c]]++] = vertex_of_tet[t];
  for (LocalIndex n = 0; n < n_nodes; ++n)
    for (std::int64_t a = start[n]; a < start[n + 1]; ++a)
      for (std::int64_t b = a + 1; b < start[n + 1]; ++b)
        pairs.emplace_back(node_tets[a], node_tets[b]);
}

}  // namespace

ElementGraph element_graph(const Model& model, const CostModel& cost, TetAdjacency adjacency,
                           const std::vector<std::pair<LocalIndex, LocalIndex>>& extra_edges) {
  const TetArrays& tets = model.tets;
  const LocalIndex n = tets.size();
  ElementGraph graph;
  graph.tet = tets_by_gid(model);
  graph.gid.resize(n);
  std::vector<std::int32_t> vertex_of_tet(n);
  for (std::int32_t v = 0; v < n; ++v) {
    vertex_of_tet[graph.tet[v]] = v;
    graph.gid[v] = tets.gid[graph.tet[v]];
  }

  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  if (adjacency == TetAdjacency::shared_face)
    face_pairs(tets, vertex_of_tet, pairs);
  else
    node_pairs(tets, vertex_of_tet, pairs);

  // Cost: each tet, plus half of every intact joint on it.
  graph.vertex_weight.assign(n, cost.tet);
  const JointArrays& joints = model.joints;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (joints.broken[j]) continue;
    const std::int32_t a = vertex_of_tet[joints.tets[2 * j]];
    const std::int32_t b = vertex_of_tet[joints.tets[2 * j + 1]];
    graph.vertex_weight[a] += 0.5 * cost.joint;
    graph.vertex_weight[b] += 0.5 * cost.joint;
    pairs.emplace_back(a, b);
  }
  for (const auto& [s, t] : extra_edges) {
    FDEM_VERIFY(s >= 0 && s < n && t >= 0 && t < n, "extra edge names a tet outside the model");
    pairs.emplace_back(vertex_of_tet[s], vertex_of_tet[t]);
  }

  // Symmetric, sorted, without duplicates or self loops.
  std::vector<std::pair<std::int32_t, std::int32_t>> directed;
  directed.reserve(2 * pairs.size());
  for (const auto& [a, b] : pairs) {
    if (a == b) continue;
    directed.emplace_back(a, b);
    directed.emplace_back(b, a);
  }
  std::sort(directed.begin(), directed.end());
  directed.erase(std::unique(directed.begin(), directed.end()), directed.end());
  graph.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  graph.adjacency.resize(directed.size());
  for (std::size_t e = 0; e < directed.size(); ++e) {
    ++graph.offsets[directed[e].first + 1];
    graph.adjacency[e] = directed[e].second;
  }
  for (std::int32_t v = 0; v < n; ++v) graph.offsets[v + 1] += graph.offsets[v];
  return graph;
}

std::vector<std::int32_t> partition_metis(const ElementGraph& graph, int n_parts) {
  if (n_parts < 1)
    throw InputError("the number of parts must be at least 1 (got " + std::to_string(n_parts) +
                     ")");
  const std::int32_t n = graph.n_vertices();
  std::vector<std::int32_t> parts(n, 0);
  if (n_parts == 1 || n == 0) return parts;
  if (n <= n_parts) {  // METIS refuses fewer vertices than parts; one tet per part is optimal
    for (std::int32_t v = 0; v < n; ++v) parts[graph.tet[v]] = v;
    return parts;
  }

  // Integer weights for METIS: mean tet ≈ 100, at least 1, total well inside idx_t.
  double total = 0.0;
  for (double w : graph.vertex_weight) total += w;
  double scale = total > 0.0 ? 100.0 * n / total : 1.0;
  scale = std::min(scale, 1.0e9 / std::max(total, 1.0e-300));
  std::vector<idx_t> vwgt(n);
  for (std::int32_t v = 0; v < n; ++v)
    vwgt[v] = std::max<idx_t>(1, static_cast<idx_t>(std::llround(graph.vertex_weight[v] * scale)));
  FDEM_VERIFY(graph.offsets.back() < static_cast<std::int64_t>(IDX_MAX),
              "element graph too large for 32-bit METIS indices");
  std::vector<idx_t> xadj(graph.offsets.begin(), graph.offsets.end());
  std::vector<idx_t> adjncy(graph.adjacency.begin(), graph.adjacency.end());

  idx_t nvtxs = n, ncon = 1, nparts = n_parts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 20240521;  // fixed: the same graph always gives the same parts
  options[METIS_OPTION_NUMBERING] = 0;
  std::vector<idx_t> part(n, 0);
  const int status =
      METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr, nullptr,
                          &nparts, nullptr, nullptr, options, &objval, part.data());
  FDEM_VERIFY(status == METIS_OK, "METIS_PartGraphKway failed with status " +
                                      std::to_string(status) + " on " + std::to_string(n) +
                                      " tets, " + std::to_string(n_parts) + " parts");
  for (std::int32_t v = 0; v < n; ++v) parts[graph.tet[v]] = static_cast<std::int32_t>(part[v]);
  return parts;
}

namespace {

struct RcbInput {
  const double* centroids;
  const double* weights;
  const GlobalId* gids;
};

// Splits elements order[begin, end) into parts [first_part, first_part + k).
void bisect(const RcbInput& in, std::vector<std::int64_t>& order, std::size_t begin,
            std::size_t end, int first_part, int k, std::vector<std::int32_t>& parts) {
  if (begin == end) return;
  if (k == 1) {
    for (std::size_t i = begin; i < end; ++i) parts[order[i]] = first_part;
    return;
  }
  // Cut across the axis along which the weight is most spread out (largest weighted variance of
  // the centroids): a light, wide base under a heavy, tall stack is cut across the stack, not
  // along the base.  The range is in a canonical order (gid at the top, (coordinate, gid) below),
  // so the sums, and the axis, are the same whatever order the elements came in.  Without weight:
  // the longest extent.  Ties → lowest axis.
  double sum_w = 0.0, sum_wx[3] = {0.0, 0.0, 0.0}, sum_wxx[3] = {0.0, 0.0, 0.0};
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = in.centroids[3 * order[begin] + a];
  for (std::size_t i = begin; i < end; ++i) {
    const double w = in.weights[order[i]];
    sum_w += w;
    for (int a = 0; a < 3; ++a) {
      const double x = in.centroids[3 * order[i] + a];
      sum_wx[a] += w * x;
      sum_wxx[a] += w * x * x;
      lo[a] = std::min(lo[a], x);
      hi[a] = std::max(hi[a], x);
    }
  }
  double spread[3];
  for (int a = 0; a < 3; ++a)
    spread[a] = sum_w > 0.0 ? sum_wxx[a] / sum_w - (sum_wx[a] / sum_w) * (sum_wx[a] / sum_w)
                            : hi[a] - lo[a];
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (spread[a] > spread[axis]) axis = a;
  // (coordinate, gid) is a total order, so the sorted range is canonical and so are the sums.
  std::sort(order.begin() + static_cast<std::ptrdiff_t>(begin),
            order.begin() + static_cast<std::ptrdiff_t>(end), [&](std::int64_t p, std::int64_t q) {
              const double cp = in.centroids[3 * p + axis], cq = in.centroids[3 * q + axis];
              return cp != cq ? cp < cq : in.gids[p] < in.gids[q];
            });
  const std::size_t n = end - begin;
  std::vector<double> prefix(n + 1, 0.0);  // prefix[s]: weight of the first s elements
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + in.weights[order[begin + i]];
  const int k_left = k / 2;
  const double target = prefix[n] * static_cast<double>(k_left) / static_cast<double>(k);
  // The split s closest to the target (first such s); with zero total weight, split by count.
  std::size_t split = 0;
  if (prefix[n] > 0.0) {
    split = static_cast<std::size_t>(std::lower_bound(prefix.begin(), prefix.end(), target) -
                                     prefix.begin());
    if (split > 0 && target - prefix[split - 1] <= prefix[split] - target) --split;
  } else {
    split = n * static_cast<std::size_t>(k_left) / static_cast<std::size_t>(k);
  }
  bisect(in, order, begin, begin + split, first_part, k_left, parts);
  bisect(in, order, begin + split, end, first_part + k_left, k - k_left, parts);
}

}  // namespace

std::vector<std::int32_t> partition_rcb(const std::vector<double>& centroids,
                                        const std::vector<double>& weights,
                                        const std::vector<GlobalId>& gids, int n_parts) {
  if (n_parts < 1)
    throw InputError("the number of parts must be at least 1 (got " + std::to_string(n_parts) +
                     ")");
  const std::size_t n = gids.size();
  FDEM_VERIFY(centroids.size() == 3 * n && weights.size() == n,
              "partition_rcb: centroids (3 per element), weights and gids disagree in length");
  for (double w : weights)
    FDEM_VERIFY(w >= 0.0 && std::isfinite(w), "partition_rcb: weights must be finite and >= 0");
  std::vector<std::int32_t> parts(n, 0);
  std::vector<std::int64_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::int64_t p, std::int64_t q) { return gids[p] < gids[q]; });
  bisect(RcbInput{centroids.data(), weights.data(), gids.data()}, order, 0, n, 0, n_parts, parts);
  return parts;
}

double imbalance(const std::vector<double>& weights, const std::vector<std::int32_t>& parts,
                 int n_parts) {
  FDEM_VERIFY(weights.size() == parts.size(), "imbalance: one part per weight");
  FDEM_VERIFY(n_parts >= 1, "imbalance: n_parts >= 1");
  std::vector<double> load(n_parts, 0.0);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    FDEM_VERIFY(parts[i] >= 0 && parts[i] < n_parts, "imbalance: part out of range");
    load[parts[i]] += weights[i];
  }
  double total = 0.0, largest = 0.0;
  for (double l : load) {
    total += l;
    largest = std::max(largest, l);
  }
  if (total <= 0.0) return 1.0;
  return largest / (total / n_parts);
}

std::vector<double> tet_centroids(const Model& model) {
  const TetArrays& tets = model.tets;
  std::vector<double> c(3 * tets.gid.size());
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int a = 0; a < 3; ++a) {
      double s = 0.0;  // fixed corner order: the same bits on every rank
      for (int k = 0; k < 4; ++k) s += model.nodes.x[3 * tets.nodes[4 * t + k] + a];
      c[3 * t + a] = 0.25 * s;
    }
  return c;
}

std::vector<double> tet_weights(const ElementGraph& graph, LocalIndex n_tets) {
  FDEM_VERIFY(graph.n_vertices() == n_tets, "tet_weights: graph is of another model");
  std::vector<double> w(n_tets);
  for (std::int32_t v = 0; v < graph.n_vertices(); ++v) w[graph.tet[v]] = graph.vertex_weight[v];
  return w;
}

std::int64_t edge_cut(const ElementGraph& graph, const std::vector<std::int32_t>& parts) {
  std::int64_t cut = 0;
  for (std::int32_t v = 0; v < graph.n_vertices(); ++v)
    for (std::int64_t e = graph.offsets[v]; e < graph.offsets[v + 1]; ++e) {
      const std::int32_t u = graph.adjacency[e];
      if (u > v && parts[graph.tet[u]] != parts[graph.tet[v]]) ++cut;
    }
  return cut;
}

HaloCounts halo_counts(const Model& model, const std::vector<std::int32_t>& parts, int n_parts) {
  const TetArrays& tets = model.tets;
  const JointArrays& joints = model.joints;
  FDEM_VERIFY(parts.size() == tets.gid.size(), "halo_counts: one part per tet");
  const LocalIndex n_nodes = model.nodes.size();
  // Node owner: part of the lowest-gid tet containing the node.
  std::vector<std::int32_t> owner(n_nodes, -1);
  for (LocalIndex t : tets_by_gid(model))
    for (int c = 0; c < 4; ++c) {
      std::int32_t& o = owner[tets.nodes[4 * t + c]];
      if (o < 0) o = parts[t];
    }
  HaloCounts h;
  h.owned_tets.assign(n_parts, 0);
  h.halo_tets.assign(n_parts, 0);
  h.halo_joints.assign(n_parts, 0);
  h.owned_nodes.assign(n_parts, 0);
  h.ghost_nodes.assign(n_parts, 0);
  for (LocalIndex i = 0; i < n_nodes; ++i)
    if (owner[i] >= 0) ++h.owned_nodes[owner[i]];
  // Per part, mark the nodes it needs (stamp = part index avoids clearing between parts).
  std::vector<std::int32_t> needed(n_nodes, -1);
  std::vector<std::vector<LocalIndex>> tets_of_part(n_parts), joints_of_part(n_parts);
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    ++h.owned_tets[parts[t]];
    tets_of_part[parts[t]].push_back(t);
    std::int32_t seen[4];
    int n_seen = 0;
    for (int c = 0; c < 4; ++c) {
      const std::int32_t p = owner[tets.nodes[4 * t + c]];
      if (p == parts[t] || std::find(seen, seen + n_seen, p) != seen + n_seen) continue;
      seen[n_seen++] = p;
      ++h.halo_tets[p];
      tets_of_part[p].push_back(t);
    }
  }
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    const std::int32_t home = parts[joints.tets[2 * j]];
    joints_of_part[home].push_back(j);
    std::int32_t seen[6];
    int n_seen = 0;
    for (int c = 0; c < 6; ++c) {
      const std::int32_t p = owner[joints.nodes[6 * j + c]];
      if (p == home || std::find(seen, seen + n_seen, p) != seen + n_seen) continue;
      seen[n_seen++] = p;
      ++h.halo_joints[p];
      joints_of_part[p].push_back(j);
    }
  }
  for (std::int32_t p = 0; p < n_parts; ++p) {
    const auto need = [&](LocalIndex node) {
      if (owner[node] != p && needed[node] != p) {
        needed[node] = p;
        ++h.ghost_nodes[p];
      }
    };
    for (LocalIndex t : tets_of_part[p])
      for (int c = 0; c < 4; ++c) need(tets.nodes[4 * t + c]);
    for (LocalIndex j : joints_of_part[p])
      for (int c = 0; c < 6; ++c) need(joints.nodes[6 * j + c]);
  }
  return h;
}

}  // namespace fdem
