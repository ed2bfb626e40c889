#include "parallel/distribution.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <type_traits>
#include <unordered_map>

#include "core/checked_cast.hpp"
#include "core/error.hpp"
#include "parallel/distribution_rows.hpp"
#include "parallel/partition.hpp"
#include "parallel/piece_directory.hpp"
#include "parallel/zoltan_partition.hpp"

namespace fdem {

using namespace distribution_rows;

namespace {

// Axis-aligned box of a tet at the current positions: lo xyz, hi xyz.
void tet_box(const Model& model, LocalIndex t, double box[6]) {
  const double* x = model.nodes.x.data();
  for (int k = 0; k < 3; ++k) {
    box[k] = std::numeric_limits<double>::infinity();
    box[3 + k] = -box[k];
  }
  for (int c = 0; c < 4; ++c) {
    const LocalIndex n = model.tets.nodes[4 * static_cast<std::size_t>(t) + c];
    for (int k = 0; k < 3; ++k) {
      box[k] = std::min(box[k], x[3 * n + k]);
      box[3 + k] = std::max(box[3 + k], x[3 * n + k]);
    }
  }
}

// Reach of each tet (m): the largest extent among the tets that share a node with it or are
// bonded to it by a joint, itself included.  An active tet of a rank (one touching a node the
// rank owns) lies within the reach of a tet the rank owns, so a contact partner of it lies within
// reach + 2 × buffer of that tet — that is how far a rank's holding must extend around each tet it
// owns.  Needs every such neighbour to be held, which the owner of a tet always does.
std::vector<double> tet_reach(const Model& model, const std::vector<double>& tet_boxes) {
  const TetArrays& tets = model.tets;
  std::vector<double> extent(static_cast<std::size_t>(tets.size()));
  std::vector<double> node_extent(static_cast<std::size_t>(model.nodes.size()), 0.0);
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    const double* b = &tet_boxes[6 * static_cast<std::size_t>(t)];
    extent[t] = std::max({b[3] - b[0], b[4] - b[1], b[5] - b[2]});
    for (int c = 0; c < 4; ++c) {
      double& e = node_extent[tets.nodes[4 * static_cast<std::size_t>(t) + c]];
      e = std::max(e, extent[t]);
    }
  }
  std::vector<double> reach(extent);
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c)
      reach[t] = std::max(reach[t], node_extent[tets.nodes[4 * static_cast<std::size_t>(t) + c]]);
  for (LocalIndex j = 0; j < model.joints.size(); ++j) {
    const LocalIndex a = model.joints.tets[2 * j], b = model.joints.tets[2 * j + 1];
    reach[a] = std::max(reach[a], extent[b]);
    reach[b] = std::max(reach[b], extent[a]);
  }
  return reach;
}

// Largest gap (m) across an intact joint: how far apart bonded tets can be.
double largest_joint_gap(const Model& model) {
  const JointArrays& joints = model.joints;
  double gap = 0.0;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (joints.broken[j]) continue;
    for (int i = 0; i < 3; ++i)
      gap = std::max(gap, (vec3_at(model.nodes.x.data(), joints.nodes[6 * j + 3 + i]) -
                           vec3_at(model.nodes.x.data(), joints.nodes[6 * j + i]))
                              .norm());
  }
  return gap;
}

// Which ranks own tets near a point: a grid of cubes (side 2 × the mean tet extent + the growth
// below), each listing the ranks whose owned tets' boxes grown by their reach touch it.  A tet goes
// to every rank listed in the cells its box grown by 2.5 × buffer (+ the largest joint gap)
// touches: a superset of "within reach + 2 × buffer of a tet that rank owns" (a pair detected
// before the next redistribution is within one buffer then, and each tet moves at most buffer/2
// until then), which is what a rank must hold, and much tighter than one box per rank when parts
// are not boxes (METIS, separate blocks) or than one margin for all when a few elements are large
// (a coarse base).  Keys are hashed cell coordinates: a collision only adds a destination.
class OwnerGrid {
 public:
  OwnerGrid(const double origin[3], double cell) : cell_(cell) { std::copy_n(origin, 3, origin_); }
  // Whether the grid can place a box (lo xyz, hi xyz) grown by `grow`: its cell indices fit in
  // 64 bits (a node flown off to 1e19 m does not) and it spans at most 2^20 cells along an axis.
  bool placeable(const double* box, double grow) const {
    for (int k = 0; k < 3; ++k) {
      const auto first = floor_to_integer<std::int64_t>((box[k] - grow - origin_[k]) / cell_);
      const auto last = floor_to_integer<std::int64_t>((box[3 + k] + grow - origin_[k]) / cell_);
      if (!first || !last || *last - *first > (std::int64_t{1} << 20)) return false;
    }
    return true;
  }
  // The cells a box (lo xyz, hi xyz) grown by `grow` touches: first xyz, last xyz (a box that
  // placeable() accepted).
  void cell_range(const double* box, double grow, std::int64_t range[6]) const {
    for (int k = 0; k < 3; ++k) {
      range[k] = static_cast<std::int64_t>(std::floor((box[k] - grow - origin_[k]) / cell_));
      range[3 + k] =
          static_cast<std::int64_t>(std::floor((box[3 + k] + grow - origin_[k]) / cell_));
    }
  }
  // Calls `visit(key, cell)` for each cell a box grown by `grow` touches.
  template <class Visit>
  void cells(const double* box, double grow, Visit&& visit) const {
    std::int64_t r[6];
    cell_range(box, grow, r);
    for (std::int64_t i = r[0]; i <= r[3]; ++i)
      for (std::int64_t j = r[1]; j <= r[4]; ++j)
        for (std::int64_t k = r[2]; k <= r[5]; ++k) {
          const std::int64_t cell[3] = {i, j, k};
          visit(key(i, j, k), cell);
        }
  }
  void add(const std::int64_t cell[3], std::int32_t rank) {
    std::vector<std::int32_t>& ranks = owners_[key(cell[0], cell[1], cell[2])];
    if (std::find(ranks.begin(), ranks.end(), rank) == ranks.end()) ranks.push_back(rank);
  }
  const std::vector<std::int32_t>* owners(std::uint64_t key) const {
    const auto it = owners_.find(key);
    return it == owners_.end() ? nullptr : &it->second;
  }

 private:
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL;
    h ^= static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint64_t>(k) * 0x165667B19E3779F9ULL + (h << 6) + (h >> 2);
    return h;
  }
  double origin_[3];
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> owners_;
};

// The test partitioner: each tet to a rank drawn from its gid and the redistribution cycle, so
// every re-partition scatters the tets anew (results must not depend on it).
std::vector<std::int32_t> random_parts(const std::vector<PartitionPoint>& points, long cycle,
                                       int ranks) {
  std::vector<std::int32_t> parts;
  parts.reserve(points.size());
  for (const PartitionPoint& p : points) {
    std::uint64_t h = static_cast<std::uint64_t>(p.gid) * 0x9E3779B97F4A7C15ULL +
                      static_cast<std::uint64_t>(cycle) * 0xC2B2AE3D27D4EB4FULL;
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 29;
    parts.push_back(static_cast<std::int32_t>(h % static_cast<std::uint64_t>(ranks)));
  }
  return parts;
}

// A claimed cell of the owner grid (integer cell coordinates) and the rank that claims it.
struct CellClaim {
  std::int64_t cell[3];
  std::int32_t rank;
};

}  // namespace

Distribution::Distribution(const Communicator& comm, DistributionSettings settings,
                           const Model& global, const TravellingState& global_state, double buffer,
                           const std::vector<std::pair<LocalIndex, LocalIndex>>& neighbours,
                           Model& local, TravellingState& local_state)
    : comm_(comm), settings_(settings), buffer_(buffer) {
  const TetArrays& tets = global.tets;
  const int ranks = comm_.size(), me = comm_.rank();
  // Node → its smallest tet gid: fixed for the whole run (fracture breaks joints, never tets).
  // The whole model is in gid order here (local index = gid − gid_offset).
  gid_offset_ = global.gid_offset;
  node_first_tet_.assign(static_cast<std::size_t>(global.nodes.size()),
                         std::numeric_limits<GlobalId>::max());
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c) {
      GlobalId& first = node_first_tet_[tets.nodes[4 * t + c]];
      first = std::min(first, tets.gid[t]);
    }

  n_tets_ = tets.size();
  // Initial partition: METIS on the element graph (faces and joints, weighted by cost), on rank 0.
  tet_owner_.assign(static_cast<std::size_t>(tets.size()), 0);
  if (ranks > 1) {
    std::string encoded;
    if (me == 0) {
      CostModel cost;
      cost.joint = settings_.joint_cost;
      const ElementGraph graph = element_graph(global, cost, TetAdjacency::shared_face, neighbours);
      const std::vector<std::int32_t> parts = partition_metis(graph, ranks);
      for (std::int32_t v = 0; v < graph.n_vertices(); ++v) tet_owner_[graph.tet[v]] = parts[v];
      encoded.assign(reinterpret_cast<const char*>(tet_owner_.data()),
                     tet_owner_.size() * sizeof(std::int32_t));
    }
    encoded = comm_.broadcast(encoded, 0);
    std::memcpy(tet_owner_.data(), encoded.data(), tet_owner_.size() * sizeof(std::int32_t));
  }
  node_owner_.resize(node_first_tet_.size());
  for (std::size_t n = 0; n < node_owner_.size(); ++n)
    node_owner_[n] = tet_owner_[static_cast<std::size_t>(node_first_tet_[n] - gid_offset_)];

  // This rank's tets: its own and every tet near them (destinations(), all tets known here).
  has_joint_state_ = !global_state.tet_joint_state.empty();
  has_contact_faces_ = !global.tets.contact_faces.empty();
  std::vector<char> rows;
  RowPacker(global, global_state, tet_owner_, node_owner_, node_first_tet_)
      .pack(destinations(global, true)[me], rows);
  local.materials = global.materials;
  local.pieces = global.pieces;
  keep_directory_block(local.pieces, comm_);  // each piece's data at its directory rank only
  local.body_names = global.body_names;
  local.body_fixed = global.body_fixed;
  local.gravity = global.gravity;
  local.joint_laws = global.joint_laws;
  local.gid_offset = global.gid_offset;
  assemble({&rows}, local, local_state);
  build_exchange(local);
  record_holders(local);
  report_.cycles = 1;
  update_report(local, false);
}

std::vector<std::vector<LocalIndex>> Distribution::destinations(
    const Model& model, bool whole, const std::vector<double>* start_reach,
    const std::vector<double>* x_also) const {
  // Senders: the tets this rank owns, or (at the start, every rank holding the whole model) all.
  const TetArrays& tets = model.tets;
  const int ranks = comm_.size();
  const auto sends = [&](LocalIndex t) { return whole || tets.is_owned(t); };
  std::vector<double> tet_boxes(6 * static_cast<std::size_t>(tets.size()));
  std::vector<double> sums = {0.0, 0.0};  // Σ extent, count of sending tets
  std::vector<double> origin(3, std::numeric_limits<double>::infinity());
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    double* b = &tet_boxes[6 * static_cast<std::size_t>(t)];
    tet_box(model, t, b);
    if (x_also)
      for (int c = 0; c < 4; ++c) {
        const LocalIndex n = model.tets.nodes[4 * static_cast<std::size_t>(t) + c];
        for (int k = 0; k < 3; ++k) {
          b[k] = std::min(b[k], (*x_also)[3 * static_cast<std::size_t>(n) + k]);
          b[3 + k] = std::max(b[3 + k], (*x_also)[3 * static_cast<std::size_t>(n) + k]);
        }
      }
    if (!sends(t)) continue;
    sums[0] += std::max({b[3] - b[0], b[4] - b[1], b[5] - b[2]});
    sums[1] += 1.0;
    for (int k = 0; k < 3; ++k) origin[k] = std::min(origin[k], b[k]);
  }
  double joint_gap = largest_joint_gap(model);
  if (!whole) {
    // One max-reduction for the origin (as minus its minimum) and the widest joint gap, one sum.
    std::vector<double> highest = {-origin[0], -origin[1], -origin[2], joint_gap};
    comm_.max_in_place(highest);
    for (int k = 0; k < 3; ++k) origin[k] = -highest[k];
    joint_gap = highest[3];
    comm_.sum_in_place(sums);
  }
  std::vector<double> reach = tet_reach(model, tet_boxes);
  if (start_reach)  // the distributed start: neighbours in other blocks count too
    for (std::size_t t = 0; t < reach.size(); ++t) reach[t] = std::max(reach[t], (*start_reach)[t]);
  const double grow = 2.5 * buffer_ + joint_gap;
  OwnerGrid grid(origin.data(), 2.0 * sums[0] / std::max(sums[1], 1.0) + grow);
  // Every sending tet must fit the grid; a tet that does not has flown off (or blown up) — every
  // rank stops with its owner's message.
  LocalError problem;
  for (LocalIndex t = 0; t < tets.size() && !problem.failed(); ++t) {
    const double* b = &tet_boxes[6 * static_cast<std::size_t>(t)];
    if (!sends(t) || grid.placeable(b, std::max(reach[t], grow))) continue;
    std::ostringstream msg;
    msg << "tetrahedron " << tets.gid[t] << " spans (" << b[0] << ", " << b[1] << ", " << b[2]
        << ") to (" << b[3] << ", " << b[4] << ", " << b[5]
        << ") m: too far from the other elements (or too large) to place among the ranks. A node "
           "has most likely flown off or blown up: check initial velocities, prescribed "
           "velocities and loads, or try a smaller time.safety.";
    problem = {ErrorKind::numerical, msg.str()};
  }
  if (whole && problem.failed()) throw NumericalFailure(problem.message);
  if (!whole) comm_.check_errors(problem);
  // Claims: the cells within reach of each tet, for its (new) owner.
  std::vector<CellClaim> claims;
  {
    std::unordered_map<std::uint64_t, std::vector<std::int32_t>> seen;
    for (LocalIndex t = 0; t < tets.size(); ++t) {
      if (!sends(t)) continue;
      const std::int32_t p = tet_owner_[t];
      grid.cells(&tet_boxes[6 * static_cast<std::size_t>(t)], reach[t],
                 [&](std::uint64_t key, const std::int64_t cell[3]) {
                   std::vector<std::int32_t>& owners_here = seen[key];
                   if (std::find(owners_here.begin(), owners_here.end(), p) == owners_here.end()) {
                     owners_here.push_back(p);
                     claims.push_back({{cell[0], cell[1], cell[2]}, p});
                   }
                 });
    }
  }
  if (whole) {
    for (const CellClaim& c : claims) grid.add(c.cell, c.rank);
  } else {
    // Each rank needs the claims on the cells its senders' grown boxes touch: the cell range of
    // every rank (O(P) numbers) says where to send each claim, so no rank receives the claims of
    // the whole domain.
    struct CellRange {
      std::int64_t r[6];  // first xyz, last xyz (last < first: sends nothing)
    };
    CellRange range{};
    double box[6] = {
        std::numeric_limits<double>::infinity(),  std::numeric_limits<double>::infinity(),
        std::numeric_limits<double>::infinity(),  -std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    bool any = false;
    for (LocalIndex t = 0; t < tets.size(); ++t) {
      if (!sends(t)) continue;
      any = true;
      for (int k = 0; k < 3; ++k) {
        box[k] = std::min(box[k], tet_boxes[6 * static_cast<std::size_t>(t) + k]);
        box[3 + k] = std::max(box[3 + k], tet_boxes[6 * static_cast<std::size_t>(t) + 3 + k]);
      }
    }
    if (any)
      grid.cell_range(box, grow, range.r);
    else
      range = {{0, 0, 0, -1, -1, -1}};
    const std::vector<CellRange> ranges = comm_.allgather(range);
    std::vector<std::vector<CellClaim>> outbox(static_cast<std::size_t>(ranks));
    for (const CellClaim& c : claims)
      for (int p = 0; p < ranks; ++p) {
        const std::int64_t* r = ranges[static_cast<std::size_t>(p)].r;
        bool inside = true;
        for (int k = 0; k < 3; ++k) inside = inside && c.cell[k] >= r[k] && c.cell[k] <= r[3 + k];
        if (inside) outbox[static_cast<std::size_t>(p)].push_back(c);
      }
    for (const CellClaim& c : comm_.exchange_sparse(outbox)) grid.add(c.cell, c.rank);
  }

  std::vector<std::vector<LocalIndex>> lists(static_cast<std::size_t>(ranks));
  std::vector<LocalIndex> sent_to(static_cast<std::size_t>(ranks), -1);
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!sends(t)) continue;
    const int owner = tet_owner_[t];
    lists[owner].push_back(t);
    sent_to[owner] = t;
    grid.cells(&tet_boxes[6 * static_cast<std::size_t>(t)], grow,
               [&](std::uint64_t key, const std::int64_t*) {
                 if (const std::vector<std::int32_t>* owners = grid.owners(key))
                   for (const std::int32_t p : *owners)
                     if (sent_to[p] != t) {
                       sent_to[p] = t;
                       lists[p].push_back(t);
                     }
               });
  }
  return lists;
}

void Distribution::redistribute(Model& model, TravellingState& state,
                                const std::vector<double>& contact_cost, double busy_seconds) {
  const auto started = std::chrono::steady_clock::now();
  // The step's exchange may skip ghosts it does not need; what moves and where is decided from
  // every held tet, so every ghost is brought up to date first.
  refresh_all_ghosts(model.nodes);
  const int ranks = comm_.size();
  const TetArrays& tets = model.tets;

  // Owned cost: tets, their intact joints (half each side), contact pairs on their first tet.
  std::vector<double> cost(static_cast<std::size_t>(tets.size()), 0.0);
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t)) cost[t] = 1.0 + (contact_cost.empty() ? 0.0 : contact_cost[t]);
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    if (!model.joints.broken[j])
      for (int side = 0; side < 2; ++side) {
        const LocalIndex t = model.joints.tets[2 * j + side];
        if (tets.is_owned(t)) cost[t] += 0.5 * settings_.joint_cost;
      }
  // One allgather: each rank's cost weights, its measured busy seconds since the last cycle and
  // the seconds its last cycle took.
  struct RankLoad {
    double cost, busy, last_cycle;
  };
  double my_cost = 0.0;
  for (LocalIndex t = 0; t < tets.size(); ++t) my_cost += cost[t];
  const std::vector<RankLoad> loads =
      comm_.allgather(RankLoad{my_cost, busy_seconds, last_cycle_seconds_});
  std::vector<double> rank_cost(loads.size());
  double busy_max = 0.0, busy_sum = 0.0, slowest_last_cycle = 0.0;
  for (std::size_t r = 0; r < loads.size(); ++r) {
    rank_cost[r] = loads[r].cost;
    busy_max = std::max(busy_max, loads[r].busy);
    busy_sum += loads[r].busy;
    slowest_last_cycle = std::max(slowest_last_cycle, loads[r].last_cycle);
  }
  account_last_cycle(slowest_last_cycle);
  const double total = std::accumulate(rank_cost.begin(), rank_cost.end(), 0.0);
  const double mean = total / ranks;
  const double before =
      mean > 0.0 ? *std::max_element(rank_cost.begin(), rank_cost.end()) / mean : 1.0;
  report_.imbalance_before = before;
  report_.max_imbalance = std::max(report_.max_imbalance, before);
  report_.imbalance = before;
  const double busy_mean = busy_sum / ranks;
  report_.migration.measured_imbalance = busy_mean > 0.0 ? busy_max / busy_mean : 1.0;

  // Re-partition when the weights say the load is uneven — and, once a re-partition has been
  // timed, only when what it would save over the next interval (the busiest rank's time above
  // the mean, if the next interval is like the last) exceeds what the last one cost.  Every rank
  // decides from the same gathered numbers.
  bool repartition = ranks > 1 && before > settings_.rebalance_threshold;
  const double gain = busy_max - busy_mean;
  if (repartition && settings_.measured_repartition && !settings_.random_parts &&
      report_.migration.last_repartition_seconds >= 0.0) {
    repartition = gain > report_.migration.last_repartition_seconds;
    if (!repartition) ++report_.migration.repartitions_declined;
  }
  if (repartition) report_.migration.predicted_gain_seconds += gain;

  long migrated = 0;
  const long rebalances_before = report_.rebalances;
  if (repartition) {
    // Weighted recursive bisection over the current centroids of the owned tets (Zoltan, each
    // rank with its own points).
    std::vector<PartitionPoint> points;
    std::vector<LocalIndex> point_tet;
    for (LocalIndex t = 0; t < tets.size(); ++t) {
      if (!tets.is_owned(t)) continue;
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += vec3_at(model.nodes.x.data(), tets.nodes[4 * t + k]);
      c *= 0.25;
      points.push_back({tets.gid[t], {c[0], c[1], c[2]}, cost[t]});
      point_tet.push_back(t);
    }
    const std::vector<std::int32_t> parts =
        settings_.random_parts ? random_parts(points, report_.cycles, ranks)
                               : partition_geometric(points, comm_, settings_.partitioner);
    std::vector<double> part_cost(static_cast<std::size_t>(ranks), 0.0);
    for (std::size_t i = 0; i < parts.size(); ++i) {
      std::int32_t& owner = tet_owner_[point_tet[i]];
      if (owner != parts[i]) ++migrated;
      owner = parts[i];
      part_cost[static_cast<std::size_t>(parts[i])] += points[i].weight;
    }
    migrated = comm_.sum(static_cast<std::int64_t>(migrated));
    comm_.sum_in_place(part_cost);
    report_.imbalance =
        mean > 0.0 ? *std::max_element(part_cost.begin(), part_cost.end()) / mean : 1.0;
    update_node_owners(model);
    ++report_.rebalances;
    report_.migrated_tets += migrated;
  }

  if (report_.rebalances > rebalances_before || !settings_.incremental) {
    // Owners moved (or the full path was asked for): every copy is sent afresh.
    TravellingState arrived;
    migrate(model, state, model, arrived);
    state = std::move(arrived);
    record_holders(model);  // incremental cycles and send_to_holders read where copies are
  } else {
    migrate_incremental(model, state);
    ++report_.migration.incremental_cycles;
  }
  ++report_.cycles;
  update_report(model, true);
  last_cycle_repartitioned_ = report_.rebalances > rebalances_before;
  last_cycle_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

std::vector<char> Distribution::send_to_holders(const std::vector<GlobalId>& tets,
                                                const std::vector<char>& records,
                                                std::size_t record_bytes) const {
  FDEM_VERIFY(records.size() == tets.size() * record_bytes, "one record per tet");
  std::vector<std::vector<char>> outbox(static_cast<std::size_t>(comm_.size()));
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const char* record = records.data() + i * record_bytes;
    auto copy = std::lower_bound(held_by_.begin(), held_by_.end(),
                                 std::pair<GlobalId, std::int32_t>{tets[i], -1});
    for (; copy != held_by_.end() && copy->first == tets[i]; ++copy)
      outbox[static_cast<std::size_t>(copy->second)].insert(
          outbox[static_cast<std::size_t>(copy->second)].end(), record, record + record_bytes);
  }
  return comm_.exchange_sparse(outbox);
}

void Distribution::update_node_owners(const Model& model) {
  // A node is owned by the owner of its first tet.  The new owner of a tet is known to the rank
  // that owned it; a directory rank (by gid) collects them, and each rank asks for the first tets
  // of the nodes of its owned tets — the nodes it will send.
  struct TetOwner {
    GlobalId tet;
    std::int32_t owner;
  };
  const int ranks = comm_.size();
  const auto directory = [&](GlobalId tet) {  // equal blocks of tet indices (gid − offset)
    return static_cast<int>(mul_div(tet - gid_offset_, ranks, std::max<GlobalId>(n_tets_, 1)));
  };
  const TetArrays& tets = model.tets;
  std::vector<std::vector<TetOwner>> posts(static_cast<std::size_t>(ranks));
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t)) posts[directory(tets.gid[t])].push_back({tets.gid[t], tet_owner_[t]});
  std::vector<TetOwner> book = comm_.exchange_sparse(posts);
  std::sort(book.begin(), book.end(),
            [](const TetOwner& a, const TetOwner& b) { return a.tet < b.tet; });
  std::vector<std::uint8_t> asking(node_owner_.size(), 0);
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t))
      for (int c = 0; c < 4; ++c) asking[tets.nodes[4 * static_cast<std::size_t>(t) + c]] = 1;
  std::vector<std::vector<GlobalId>> questions(static_cast<std::size_t>(ranks));
  for (std::size_t n = 0; n < asking.size(); ++n)
    if (asking[n]) questions[directory(node_first_tet_[n])].push_back(node_first_tet_[n]);
  for (auto& q : questions) {
    std::sort(q.begin(), q.end());
    q.erase(std::unique(q.begin(), q.end()), q.end());
  }
  std::vector<int> asker;
  const std::vector<GlobalId> asked = comm_.exchange_sparse(questions, &asker);
  std::vector<std::vector<TetOwner>> answers(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < asked.size(); ++i) {
    const auto it = std::lower_bound(book.begin(), book.end(), asked[i],
                                     [](const TetOwner& a, GlobalId gid) { return a.tet < gid; });
    FDEM_VERIFY(it != book.end() && it->tet == asked[i], "every tet has an owner on record");
    answers[static_cast<std::size_t>(asker[i])].push_back(*it);
  }
  std::vector<TetOwner> known = comm_.exchange_sparse(answers);
  std::sort(known.begin(), known.end(),
            [](const TetOwner& a, const TetOwner& b) { return a.tet < b.tet; });
  for (std::size_t n = 0; n < asking.size(); ++n) {
    if (!asking[n]) continue;
    const auto it = std::lower_bound(known.begin(), known.end(), node_first_tet_[n],
                                     [](const TetOwner& a, GlobalId gid) { return a.tet < gid; });
    FDEM_VERIFY(it != known.end() && it->tet == node_first_tet_[n], "the directory answered");
    node_owner_[n] = it->owner;
  }
}

}  // namespace fdem
