#include "parallel/boundary_matching.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "core/error.hpp"
#include "core/joint_placement.hpp"
#include "parallel/directory_hash.hpp"

namespace fdem {

namespace {

using Cell = std::array<std::int64_t, 3>;

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    return static_cast<std::size_t>(directory_hash({c[0], c[1], c[2]}));
  }
};

// Tolerance cells per directory block and axis.
constexpr std::int64_t block_cells = 1024;

// ⌊c / k⌋ for k > 0.
std::int64_t floor_div(std::int64_t c, std::int64_t k) {
  std::int64_t q = c / k;
  if (c % k != 0 && c < 0) --q;
  return q;
}

// A boundary node on its way to a directory rank.
struct PosNode {
  std::int64_t cell[3];  // tolerance cell
  std::int64_t mesh_node;
  double x[3];  // m
  std::int32_t body, piece, home, unused;
};

}  // namespace

bool match_order(const NodeMatch& p, const NodeMatch& q) {
  if (p.body != q.body) return p.body < q.body;
  if (p.mesh_node != q.mesh_node) return p.mesh_node < q.mesh_node;
  return p.target < q.target;
}

std::vector<NodeMatch> match_boundary_points(const Scene& scene,
                                             const std::vector<BoundaryPoint>& points, double tol,
                                             const Communicator& comm,
                                             std::vector<std::string>* far) {
  const int ranks = comm.size();
  std::vector<char> bonded(scene.bodies.size());
  std::vector<std::vector<std::int32_t>> as_a(scene.bodies.size());  // interfaces it is A of
  for (std::size_t b = 0; b < scene.bodies.size(); ++b)
    bonded[b] = scene.bodies[b].joints == JointPlacement::interfaces;
  for (std::size_t k = 0; k < scene.interfaces.size(); ++k)
    as_a[static_cast<std::size_t>(scene.interfaces[k].body_a)].push_back(
        static_cast<std::int32_t>(k));

  // Each point to its home block's rank (home = 1) and to the ranks of the blocks its cell's
  // neighbours lie in.
  std::vector<std::vector<PosNode>> outbox(static_cast<std::size_t>(ranks));
  far->assign(points.size(), std::string());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const BoundaryPoint& point = points[i];
    const Vec3 x(point.x[0], point.x[1], point.x[2]);
    Cell cell{};
    try {
      cell = tolerance_cell(x, tol);
    } catch (const InputError& e) {
      (*far)[i] = e.what();
      continue;
    }
    std::int64_t options[3][3], home[3];
    int n_options[3];
    for (int k = 0; k < 3; ++k) {
      home[k] = floor_div(cell[k], block_cells);
      const std::int64_t r = cell[k] - home[k] * block_cells;
      n_options[k] = 0;
      options[k][n_options[k]++] = home[k];
      if (r == 0) options[k][n_options[k]++] = home[k] - 1;
      if (r == block_cells - 1) options[k][n_options[k]++] = home[k] + 1;
    }
    const int home_rank = directory_rank({home[0], home[1], home[2]}, ranks);
    std::vector<int> to;
    for (int a = 0; a < n_options[0]; ++a)
      for (int b = 0; b < n_options[1]; ++b)
        for (int c = 0; c < n_options[2]; ++c)
          to.push_back(directory_rank({options[0][a], options[1][b], options[2][c]}, ranks));
    std::sort(to.begin(), to.end());
    to.erase(std::unique(to.begin(), to.end()), to.end());
    PosNode p{{cell[0], cell[1], cell[2]},
              point.mesh_node,
              {point.x[0], point.x[1], point.x[2]},
              point.body,
              point.piece,
              0,
              0};
    for (int r : to) {
      p.home = r == home_rank;
      outbox[static_cast<std::size_t>(r)].push_back(p);
    }
  }

  // Directory: the partners of the nodes this rank answers for.
  std::vector<int> asker;
  std::vector<PosNode> seen = comm.exchange(outbox, &asker);
  release(outbox);
  std::vector<std::size_t> order(seen.size());
  std::iota(order.begin(), order.end(), 0);
  const auto same_node = [&](std::size_t a, std::size_t b) {
    return seen[a].body == seen[b].body && seen[a].mesh_node == seen[b].mesh_node;
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (seen[a].body != seen[b].body) return seen[a].body < seen[b].body;
    return seen[a].mesh_node != seen[b].mesh_node ? seen[a].mesh_node < seen[b].mesh_node : a < b;
  });
  std::unordered_map<Cell, std::vector<std::size_t>, CellHash> grid;  // each node once
  for (std::size_t i = 0; i < order.size(); ++i)
    if (i == 0 || !same_node(order[i], order[i - 1]))
      grid[{seen[order[i]].cell[0], seen[order[i]].cell[1], seen[order[i]].cell[2]}].push_back(
          order[i]);
  std::vector<std::vector<NodeMatch>> answers(static_cast<std::size_t>(ranks));
  std::vector<NodeMatch> found;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    bool home = false;
    for (; j < order.size() && same_node(order[j], order[i]); ++j)
      home = home || seen[order[j]].home;
    const PosNode& m = seen[order[i]];
    const auto b = static_cast<std::size_t>(m.body);
    found.clear();
    if (home) {
      // The serial builder's search: nodes in the 27 cells around m's, within tol.
      const Vec3 x(m.x[0], m.x[1], m.x[2]);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const int d[3] = {dx, dy, dz};
            Cell c{};
            bool inside = true;
            for (int k = 0; k < 3; ++k) {
              const std::int64_t limit = d[k] < 0 ? std::numeric_limits<std::int64_t>::min()
                                                  : std::numeric_limits<std::int64_t>::max();
              inside = inside && (d[k] == 0 || m.cell[k] != limit);
              c[k] = inside ? m.cell[k] + d[k] : 0;
            }
            if (!inside) continue;
            const auto g = grid.find(c);
            if (g == grid.end()) continue;
            for (std::size_t u : g->second) {
              const PosNode& n = seen[u];
              if (n.body == m.body && n.piece == m.piece) continue;
              if (!((Vec3(n.x[0], n.x[1], n.x[2]) - x).norm() <= tol)) continue;
              if (n.body == m.body) {
                if (bonded[b] && n.piece > m.piece)
                  found.push_back({m.mesh_node, n.mesh_node, m.body, n.piece});
                continue;
              }
              for (std::int32_t k : as_a[b])
                if (scene.interfaces[static_cast<std::size_t>(k)].body_b == n.body)
                  found.push_back({m.mesh_node, n.mesh_node, m.body, -1 - k});
            }
          }
      // The lowest-numbered partner per piece or interface.
      std::sort(found.begin(), found.end(), [](const NodeMatch& p, const NodeMatch& q) {
        return p.target != q.target ? p.target < q.target : p.partner < q.partner;
      });
      found.erase(
          std::unique(found.begin(), found.end(),
                      [](const NodeMatch& p, const NodeMatch& q) { return p.target == q.target; }),
          found.end());
      for (std::size_t k = i; k < j; ++k)
        if (seen[order[k]].home) {
          std::vector<NodeMatch>& to = answers[static_cast<std::size_t>(asker[order[k]])];
          to.insert(to.end(), found.begin(), found.end());
        }
    }
    i = j;
  }
  release(seen);
  grid.clear();
  std::vector<NodeMatch> matches = comm.exchange(answers);
  std::sort(matches.begin(), matches.end(), match_order);
  return matches;
}

}  // namespace fdem
