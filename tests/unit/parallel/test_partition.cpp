// Decomposition layer: element graph, METIS and RCB partitions, imbalance, halo counts.
#include <algorithm>
#include <catch2/catch.hpp>
#include <numeric>
#include <random>
#include <set>

#include "core/error.hpp"
#include "core/model_builder.hpp"
#include "parallel/partition.hpp"

using namespace fdem;

namespace {

// nx·ny·nz unit cubes of 6 Kuhn tets each (conforming, all around the cube's main diagonal).
BodyMesh kuhn_box(int nx, int ny, int nz) {
  BodyMesh m;
  m.source = "test box";
  const auto node = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.coords.insert(m.coords.end(), {1.0 * i, 1.0 * j, 1.0 * k});
  static constexpr int kPaths[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                       {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& path : kPaths) {
          LocalIndex v[4];
          for (int c = 0; c < 4; ++c)
            v[c] = node(i + (path[c] & 1), j + ((path[c] >> 1) & 1), k + ((path[c] >> 2) & 1));
          const auto p = [&](int c) {
            return Vec3(m.coords[3 * v[c]], m.coords[3 * v[c] + 1], m.coords[3 * v[c] + 2]);
          };
          if ((p(1) - p(0)).cross(p(2) - p(0)).dot(p(3) - p(0)) < 0) std::swap(v[2], v[3]);
          m.tets.insert(m.tets.end(), v, v + 4);
        }
  return m;
}

Scene box_scene(bool jointed) {
  Scene s;
  s.source_path = "test.yaml";
  MaterialSpec m;
  m.name = "rock";
  m.density = 2500;
  m.elastic.young = 1e9;
  m.elastic.poisson = 0.25;
  if (jointed) {
    FractureSpec f;
    f.tensile_strength = 1e6;
    f.cohesion = 2e6;
    f.friction_angle_deg = 30;
    f.energy_I = 10;
    f.energy_II = 50;
    m.fracture = f;
  }
  s.materials.push_back(m);
  BodySpec body;
  body.name = "box";
  body.material = 0;
  body.joints = jointed ? JointPlacement::all : JointPlacement::none;
  s.bodies.push_back(body);
  return s;
}

Model box_model(int nx, int ny, int nz, bool jointed = false) {
  return build_model(box_scene(jointed), {kuhn_box(nx, ny, nz)});
}

// Interior triangles of a Kuhn box: 4T = 2·interior + boundary, boundary = 2 per boundary square.
std::int64_t interior_faces(int nx, int ny, int nz) {
  const std::int64_t cubes = std::int64_t(nx) * ny * nz;
  const std::int64_t squares =
      2 * (std::int64_t(nx) * ny + std::int64_t(ny) * nz + std::int64_t(nx) * nz);
  return (4 * 6 * cubes - 2 * squares) / 2;
}

// The same model with its tets stored in reverse (gids travel with the tets).
Model reversed_tets(const Model& in) {
  Model m = in;
  const LocalIndex n = in.tets.size();
  std::vector<LocalIndex> new_index(n);
  for (LocalIndex t = 0; t < n; ++t) {
    const LocalIndex r = n - 1 - t;
    new_index[t] = r;
    m.tets.gid[r] = in.tets.gid[t];
    for (int c = 0; c < 4; ++c) m.tets.nodes[4 * r + c] = in.tets.nodes[4 * t + c];
    m.tets.volume0[r] = in.tets.volume0[t];
  }
  for (auto& t : m.joints.tets) t = new_index[t];
  build_tet_force_order(m.tets, m.tet_force_order);
  return m;
}

std::vector<std::int32_t> random_parts(std::size_t n, int n_parts, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, n_parts - 1);
  std::vector<std::int32_t> parts(n);
  for (auto& p : parts) p = pick(rng);
  return parts;
}

void check_covers(const std::vector<std::int32_t>& parts, std::size_t n, int n_parts) {
  REQUIRE(parts.size() == n);
  std::vector<std::int64_t> count(n_parts, 0);
  for (auto p : parts) {
    REQUIRE(p >= 0);
    REQUIRE(p < n_parts);
    ++count[p];
  }
  for (int p = 0; p < n_parts; ++p) CHECK(count[p] > 0);
}

}  // namespace

TEST_CASE("element graph of a box: one edge per interior face, unit weights", "[partition]") {
  const Model model = box_model(4, 3, 5);
  const ElementGraph g = element_graph(model);
  REQUIRE(g.n_vertices() == 6 * 60);
  CHECK(g.n_edges() == interior_faces(4, 3, 5));  // 1288
  for (std::int32_t v = 0; v < g.n_vertices(); ++v) {
    const std::int64_t degree = g.offsets[v + 1] - g.offsets[v];
    CHECK(degree >= 1);
    CHECK(degree <= 4);
    CHECK(g.vertex_weight[v] == 1.0);
    if (v > 0) CHECK(g.gid[v - 1] < g.gid[v]);
    for (std::int64_t e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
      const std::int32_t u = g.adjacency[e];
      CHECK(u != v);
      // symmetric
      CHECK(std::binary_search(g.adjacency.begin() + g.offsets[u],
                               g.adjacency.begin() + g.offsets[u + 1], v));
    }
  }
  const ElementGraph by_node = element_graph(model, {}, TetAdjacency::shared_node);
  CHECK(by_node.n_edges() > 5 * g.n_edges());
}

TEST_CASE("element graph of a jointed box: joints are the edges and add to the cost",
          "[partition]") {
  const Model model = box_model(3, 3, 2, /*jointed=*/true);
  REQUIRE(model.joints.size() == interior_faces(3, 3, 2));
  const CostModel cost{2.0, 0.5};
  const ElementGraph g = element_graph(model, cost);
  // split nodes: no tet shares a face with another, every neighbour comes through a joint
  CHECK(g.n_edges() == model.joints.size());
  const double total = std::accumulate(g.vertex_weight.begin(), g.vertex_weight.end(), 0.0);
  CHECK(total == Approx(2.0 * model.tets.size() + 0.5 * model.joints.size()).epsilon(1e-14));
  // a broken joint is no longer an edge nor a cost
  Model broken = model;
  broken.joints.broken[0] = 1;
  const ElementGraph gb = element_graph(broken, cost);
  CHECK(gb.n_edges() == model.joints.size() - 1);
}

TEST_CASE("element graph and METIS parts do not depend on the local tet order", "[partition]") {
  const Model model = box_model(6, 5, 4);
  const Model reversed = reversed_tets(model);
  const ElementGraph a = element_graph(model), b = element_graph(reversed);
  CHECK(a.gid == b.gid);
  CHECK(a.offsets == b.offsets);
  CHECK(a.adjacency == b.adjacency);
  const auto pa = partition_metis(a, 3), pb = partition_metis(b, 3);
  for (LocalIndex t = 0; t < model.tets.size(); ++t) CHECK(pa[t] == pb[model.tets.size() - 1 - t]);
  CHECK(partition_metis(a, 3) == pa);  // and the same again
}

TEST_CASE("METIS partition of a 4800-tet box: covers, balances, cuts far less than random",
          "[partition]") {
  const Model model = box_model(10, 10, 8);
  const ElementGraph g = element_graph(model);
  const std::vector<double> w = tet_weights(g, model.tets.size());
  for (int n_parts : {2, 3, 4, 7}) {
    CAPTURE(n_parts);
    const auto parts = partition_metis(g, n_parts);
    check_covers(parts, model.tets.size(), n_parts);
    const double imb = imbalance(w, parts, n_parts);
    CHECK(imb <= 1.04);  // METIS k-way default tolerance is 1.03
    const std::int64_t cut = edge_cut(g, parts);
    const std::int64_t random_cut = edge_cut(g, random_parts(model.tets.size(), n_parts, 7));
    CHECK(cut * 10 < random_cut);
    // a plane cut of the 10x10x8 box crosses 200 faces; k parts need at least ~ that many
    CHECK(cut <= 200 * (n_parts - 1) * 3 / 2);
  }
}

TEST_CASE("METIS: one part, fewer tets than parts, tets without neighbours", "[partition]") {
  const Model model = box_model(1, 1, 1);  // 6 tets
  const ElementGraph g = element_graph(model);
  CHECK(partition_metis(g, 1) == std::vector<std::int32_t>(6, 0));
  const auto eight = partition_metis(g, 8);
  CHECK(std::set<std::int32_t>(eight.begin(), eight.end()).size() == 6);
  check_covers(partition_metis(g, 6), 6, 6);
  CHECK_THROWS_AS(partition_metis(g, 0), InputError);
  // barely more tets than parts: METIS still gives every part a tet
  const Model twelve = box_model(2, 1, 1);
  for (int n_parts : {5, 7, 11})
    check_covers(partition_metis(element_graph(twelve), n_parts), 12, n_parts);
  // a graph without edges (separate tets): METIS still balances the weights
  const Model many = box_model(6, 6, 6);
  ElementGraph loose = element_graph(many);
  std::fill(loose.offsets.begin(), loose.offsets.end(), 0);
  loose.adjacency.clear();
  const auto parts = partition_metis(loose, 4);
  check_covers(parts, many.tets.size(), 4);
  CHECK(imbalance(tet_weights(loose, many.tets.size()), parts, 4) <= 1.04);
}

TEST_CASE("RCB balances uniform and random weights for 2, 3, 4, 7 parts", "[partition]") {
  const Model model = box_model(10, 10, 8);
  const std::vector<double> c = tet_centroids(model);
  const std::vector<double> unit(model.tets.size(), 1.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> spread(1.0, 3.0);
  std::vector<double> varied(model.tets.size());
  for (auto& w : varied) w = spread(rng);
  const ElementGraph g = element_graph(model);
  for (int n_parts : {2, 3, 4, 7}) {
    CAPTURE(n_parts);
    const auto parts = partition_rcb(c, unit, model.tets.gid, n_parts);
    check_covers(parts, model.tets.size(), n_parts);
    // each cut is off by at most half an element: 4800/7 ≈ 686 tets per part
    CHECK(imbalance(unit, parts, n_parts) <= 1.005);
    const auto parts_w = partition_rcb(c, varied, model.tets.gid, n_parts);
    check_covers(parts_w, model.tets.size(), n_parts);
    CHECK(imbalance(varied, parts_w, n_parts) <= 1.01);
    // a spatial cut is compact: far below a random partition's cut
    CHECK(edge_cut(g, parts) * 10 < edge_cut(g, random_parts(model.tets.size(), n_parts, 3)));
  }
}

TEST_CASE("RCB is deterministic and independent of the input order", "[partition]") {
  const Model model = box_model(8, 6, 5);
  const std::size_t n = model.tets.gid.size();
  const std::vector<double> c = tet_centroids(model);
  std::vector<double> w(n);
  for (std::size_t i = 0; i < n; ++i) w[i] = 1.0 + 0.1 * static_cast<double>(i % 7);
  for (int n_parts : {2, 3, 5, 7}) {
    CAPTURE(n_parts);
    const auto parts = partition_rcb(c, w, model.tets.gid, n_parts);
    CHECK(partition_rcb(c, w, model.tets.gid, n_parts) == parts);
    // permute the elements (centroid, weight and gid together)
    std::vector<std::size_t> perm(n);
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(n_parts));
    std::vector<double> pc(3 * n), pw(n);
    std::vector<GlobalId> pg(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) pc[3 * i + a] = c[3 * perm[i] + a];
      pw[i] = w[perm[i]];
      pg[i] = model.tets.gid[perm[i]];
    }
    const auto permuted = partition_rcb(pc, pw, pg, n_parts);
    std::size_t same = 0;
    for (std::size_t i = 0; i < n; ++i) same += permuted[i] == parts[perm[i]];
    CHECK(same == n);
  }
}

TEST_CASE("RCB: ties by gid, clusters, few elements, zero weights", "[partition]") {
  // four elements at one point: only the gids order them
  const std::vector<double> same_point(12, 0.5);
  const auto p = partition_rcb(same_point, {1, 1, 1, 1}, {40, 10, 30, 20}, 2);
  CHECK(p == std::vector<std::int32_t>{1, 0, 1, 0});
  // two far clusters, two parts: each cluster whole
  std::vector<double> c;
  std::vector<GlobalId> gid;
  for (int i = 0; i < 10; ++i) {
    c.insert(c.end(), {0.01 * i, 0.0, 0.0});
    c.insert(c.end(), {100.0 + 0.01 * i, 0.0, 0.0});
    gid.push_back(2 * i);
    gid.push_back(2 * i + 1);
  }
  const auto clusters = partition_rcb(c, std::vector<double>(20, 1.0), gid, 2);
  for (int i = 0; i < 20; ++i) CHECK(clusters[i] == i % 2);
  // fewer elements than parts: all different
  const auto few = partition_rcb({0, 0, 0, 1, 0, 0, 2, 0, 0}, {1, 1, 1}, {0, 1, 2}, 7);
  CHECK(std::set<std::int32_t>(few.begin(), few.end()).size() == 3);
  // zero weights: split by count
  const auto zero = partition_rcb(c, std::vector<double>(20, 0.0), gid, 4);
  std::vector<int> count(4, 0);
  for (auto q : zero) ++count[q];
  CHECK(count == std::vector<int>{5, 5, 5, 5});
  CHECK(partition_rcb({}, {}, {}, 3).empty());
  CHECK_THROWS_AS(partition_rcb(c, std::vector<double>(20, 1.0), gid, 0), InputError);
}

TEST_CASE("imbalance is max part weight over mean part weight", "[partition]") {
  CHECK(imbalance({1, 2, 3, 4}, {0, 0, 1, 1}, 2) == Approx(7.0 / 5.0).epsilon(1e-15));
  // an empty part counts in the mean
  CHECK(imbalance({1, 2, 3, 4}, {0, 0, 1, 1}, 3) == Approx(7.0 / (10.0 / 3.0)).epsilon(1e-15));
  CHECK(imbalance({2, 2, 2}, {0, 1, 2}, 3) == 1.0);
  CHECK(imbalance({}, {}, 4) == 1.0);
}

TEST_CASE("halo counts of two tets sharing a face", "[partition]") {
  Scene scene = box_scene(false);
  BodyMesh m;
  m.source = "test";
  m.coords = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  m.tets = {0, 1, 2, 3, 1, 4, 2, 3};  // share face 1-2-3; tet 2 adds node 4
  const Model model = build_model(scene, {m});
  REQUIRE(model.tets.size() == 2);
  std::vector<std::int32_t> parts(2);
  const LocalIndex first = model.tet_force_order[0], second = model.tet_force_order[1];
  parts[first] = 0;
  parts[second] = 1;
  const HaloCounts h = halo_counts(model, parts, 2);
  // the lower-gid tet's part owns its four nodes; part 1 owns only the other tet's fifth node
  CHECK(h.owned_nodes == std::vector<std::int64_t>{4, 1});
  CHECK(h.owned_tets == std::vector<std::int64_t>{1, 1});
  // part 0 owns 3 nodes of the second tet: holds it as halo, needs its fifth node as a ghost;
  // part 1's tet is its own and needs the three shared nodes as ghosts
  CHECK(h.halo_tets == std::vector<std::int64_t>{1, 0});
  CHECK(h.ghost_nodes == std::vector<std::int64_t>{1, 3});
}

TEST_CASE("halo of METIS parts: face graph against node graph, joints in the halo", "[partition]") {
  const Model model = box_model(10, 10, 8);
  const ElementGraph by_face = element_graph(model);
  const ElementGraph by_node = element_graph(model, {}, TetAdjacency::shared_node);
  for (int n_parts : {2, 4}) {
    CAPTURE(n_parts);
    const HaloCounts f = halo_counts(model, partition_metis(by_face, n_parts), n_parts);
    const HaloCounts nd = halo_counts(model, partition_metis(by_node, n_parts), n_parts);
    const auto total = [](const std::vector<std::int64_t>& v) {
      return std::accumulate(v.begin(), v.end(), std::int64_t{0});
    };
    CHECK(total(f.owned_nodes) == model.nodes.size());
    CHECK(total(f.owned_tets) == model.tets.size());
    CAPTURE(total(f.halo_tets), total(nd.halo_tets), total(f.ghost_nodes), total(nd.ghost_nodes));
    CHECK(total(f.halo_tets) > 0);
    // the face graph's halo is within 35 % of the node graph's (which models it exactly); METIS's
    // cuts depend on the element order: 1.29 with the isotropic Morton order, 1.0-1.25 before
    CHECK(total(f.halo_tets) <= 1.35 * total(nd.halo_tets));
    // halo well below the whole mesh: a layer along each cut (3 cuts of 4 parts: 27 %)
    CHECK(total(f.halo_tets) < 0.3 * model.tets.size());
  }
  // jointed box: every joint crossing the cut is in the other part's halo
  const Model jointed = box_model(6, 6, 4, true);
  const auto parts = partition_metis(element_graph(jointed), 2);
  const HaloCounts h = halo_counts(jointed, parts, 2);
  std::int64_t crossing = 0;
  for (LocalIndex j = 0; j < jointed.joints.size(); ++j)
    crossing += parts[jointed.joints.tets[2 * j]] != parts[jointed.joints.tets[2 * j + 1]];
  CHECK(crossing > 0);
  CHECK(h.halo_joints[0] + h.halo_joints[1] == crossing);
  // split nodes: a tet's nodes are its own, so no tet is in the other part's halo
  CHECK(h.halo_tets[0] + h.halo_tets[1] == 0);
}

TEST_CASE("RCB cuts across the axis where the weight spreads most, not the longest extent",
          "[parallel]") {
  // A light base 3 m wide (x) under a heavy stack 2 m tall (z): the box is longest in x, but the
  // weight spreads along z, so the cut must separate the lower stack from the upper stack.
  std::vector<double> centroids, weights;
  std::vector<fdem::GlobalId> gids;
  for (int i = 0; i < 100; ++i) {  // base
    centroids.insert(centroids.end(), {-1.5 + 3.0 * (i + 0.5) / 100.0, 0.0, 0.0});
    weights.push_back(1.0);
    gids.push_back(i);
  }
  for (int i = 0; i < 100; ++i) {  // stack
    centroids.insert(centroids.end(), {(i % 2 ? 0.1 : -0.1), 0.0, 0.1 + 1.9 * (i + 0.5) / 100.0});
    weights.push_back(50.0);
    gids.push_back(100 + i);
  }
  const std::vector<std::int32_t> parts = fdem::partition_rcb(centroids, weights, gids, 2);
  double highest_low = -1e9, lowest_high = 1e9;
  for (int i = 100; i < 200; ++i) {
    const double z = centroids[3 * i + 2];
    const int low_part = parts[100];  // the bottom of the stack
    if (parts[i] == low_part)
      highest_low = std::max(highest_low, z);
    else
      lowest_high = std::min(lowest_high, z);
  }
  CHECK(highest_low < lowest_high);  // a horizontal cut through the stack
  CHECK(fdem::imbalance(weights, parts, 2) < 1.05);
}
