// Decomposition layer: which rank owns which tet.  Serial, pure functions (no MPI); the MPI side
// (distribution, migration, halo) uses their results.
//
// - element_graph + partition_metis: the initial partition, METIS k-way on the element graph
//   (tets adjacent through a shared face or an intact joint), vertices weighted by cost.
// - partition_rcb: the re-balance by space at a contact-detection cycle, weighted recursive
//   coordinate bisection over tet centroids.
// - imbalance, edge_cut, halo_counts: what a partition costs, for reports and tests.
//
// Every result is deterministic and independent of the local storage order: graph vertices are
// the tets in ascending global id, METIS runs with a fixed seed, RCB breaks ties by global id.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/model.hpp"
#include "core/types.hpp"

namespace fdem {

// Relative cost of the work a tet brings to its rank (the unit is arbitrary; only ratios matter).
struct CostModel {
  double tet = 1.0;    // internal force of one tet
  double joint = 1.0;  // one intact joint (three integration points), half to each of its two tets
};

// When two tets are neighbours in the graph, besides being bonded by an intact joint.
// shared_face (default): the dual graph METIS is made for (≤ 4 mesh neighbours per tet); a cut
//   face is a unit of partition surface, and the halo (tets touching a node owned elsewhere) is a
//   layer along that surface, so minimising cut faces nearly minimises the halo.  On a 4800-tet
//   Kuhn box it has 15× fewer edges than shared_node (9080 vs 137812) and its METIS halo is
//   6–18 % larger for 2–7 parts (docs/parallel.md).
// shared_node: every tet sharing a node (the exact "puts force on my node" relation); kept to
//   compare the halo both give (tests/unit/parallel/test_partition.cpp).
// In a `joints: all` body tets share no node at all (every tet has its own copies); the joints are
// what connects them, so joints are always edges.
enum class TetAdjacency { shared_face, shared_node };

// Compressed sparse row graph over the model's tets.  Vertex v is the tet with the v-th smallest
// global id, so the graph (and METIS's answer) does not depend on the local storage order.
struct ElementGraph {
  std::vector<LocalIndex> tet;          // local tet index of vertex v
  std::vector<GlobalId> gid;            // its global id (ascending)
  std::vector<std::int64_t> offsets;    // neighbours of v: adjacency[offsets[v], offsets[v+1])
  std::vector<std::int32_t> adjacency;  // vertex indices, ascending within a row, no self loops
  std::vector<double> vertex_weight;    // cost (CostModel units)

  std::int32_t n_vertices() const { return static_cast<std::int32_t>(tet.size()); }
  std::int64_t n_edges() const { return static_cast<std::int64_t>(adjacency.size()) / 2; }
};

// The graph of all tets in `model` (call it on the whole model, before distribution).
// `extra_edges`: more pairs of local tets to keep together (e.g. contact candidate pairs at t = 0,
// so that separate blocks touching each other land on the same rank).  Broken joints are not edges.
ElementGraph element_graph(const Model& model, const CostModel& cost = {},
                           TetAdjacency adjacency = TetAdjacency::shared_face,
                           const std::vector<std::pair<LocalIndex, LocalIndex>>& extra_edges = {});

// METIS k-way partition of the graph into n_parts ≥ 1: part (0 … n_parts−1) per LOCAL tet index.
// n_parts = 1 → all 0 without calling METIS; at most n_parts vertices → vertex v gets part v
// (some parts empty).  Fixed seed: the same graph gives the same parts on every machine run.
// Weights are scaled to integers (a tet of mean weight ≈ 100) for METIS.
std::vector<std::int32_t> partition_metis(const ElementGraph& graph, int n_parts);

// Weighted recursive coordinate bisection: `centroids` 3 per element, `weights` ≥ 0 and `gids`
// one per element, any n_parts ≥ 1.  Each cut splits the weight of a box in the ratio of the parts
// on either side (⌊k/2⌋ : ⌈k/2⌉), across the axis of largest weighted variance of the centroids
// (longest extent without weight); elements are ordered by gid, then by (coordinate, gid), so the
// result for each gid is the same whatever order the elements come in.
// Returns the part per element (input order).
std::vector<std::int32_t> partition_rcb(const std::vector<double>& centroids,
                                        const std::vector<double>& weights,
                                        const std::vector<GlobalId>& gids, int n_parts);

// Load imbalance = max over parts of the part's weight / mean part weight (1 = perfect;
// an empty total gives 1).
double imbalance(const std::vector<double>& weights, const std::vector<std::int32_t>& parts,
                 int n_parts);

// Current centroid of every local tet (3 per tet, m).
std::vector<double> tet_centroids(const Model& model);

// Per-vertex weights of the graph in local tet order (for partition_rcb / imbalance).
std::vector<double> tet_weights(const ElementGraph& graph, LocalIndex n_tets);

// Number of graph edges whose two tets are in different parts (`parts` per local tet).
std::int64_t edge_cut(const ElementGraph& graph, const std::vector<std::int32_t>& parts);

// What owner-computes costs each part, given a part per local tet.  A node is owned by the part of
// the lowest-gid tet that contains it.  A part holds as halo every tet of another part that has a
// node it owns, and every joint (owned by tet A's part) with a node it owns; its ghost nodes are
// the nodes of its owned and halo tets and joints that it does not own.
struct HaloCounts {
  std::vector<std::int64_t> owned_tets, halo_tets, halo_joints, owned_nodes, ghost_nodes;
};
HaloCounts halo_counts(const Model& model, const std::vector<std::int32_t>& parts, int n_parts);

}  // namespace fdem
