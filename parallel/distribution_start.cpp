// The distributed start of a Distribution: each rank holds its block of the model
// (parallel/distributed_build), every tet of it owned here; what is missing is the halo.
#include <algorithm>
#include <numeric>

#include "core/error.hpp"
#include "core/fields.hpp"
#include "parallel/distribution.hpp"
#include "parallel/distribution_rows.hpp"

namespace fdem {

using namespace distribution_rows;

namespace {

// Reorders rows [first, first + order.size()) of `values` (`width` values per row): new row
// first + i is old row order[i].
template <class T>
void permute_tail(std::vector<T>& values, std::size_t width, std::size_t first,
                  const std::vector<std::size_t>& order) {
  std::vector<T> tail(order.size() * width);
  for (std::size_t i = 0; i < order.size(); ++i)
    std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(order[i] * width), width,
                tail.begin() + static_cast<std::ptrdiff_t>(i * width));
  std::copy(tail.begin(), tail.end(), values.begin() + static_cast<std::ptrdiff_t>(first * width));
}

// Grows `values` from `old_rows` to `rows` rows, moving the old rows down by `shift` rows.
template <class T>
void open_rows(std::vector<T>& values, std::size_t width, std::size_t old_rows, std::size_t rows,
               std::size_t shift) {
  resize_exact(values, rows * width);
  std::move_backward(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(old_rows * width),
                     values.begin() + static_cast<std::ptrdiff_t>((old_rows + shift) * width));
}

}  // namespace

Distribution::Distribution(const Communicator& comm, DistributionSettings settings,
                           DistributedModel start, double buffer, Model& local,
                           TravellingState& local_state)
    : comm_(comm), settings_(settings), buffer_(buffer) {
  n_tets_ = start.n_tets;
  gid_offset_ = start.model.gid_offset;
  // The blocks are the initial partition: every local tet is owned here.
  tet_owner_.assign(static_cast<std::size_t>(start.model.tets.size()), comm_.rank());
  node_owner_ = std::move(start.node_owner);
  node_first_tet_ = std::move(start.node_first_tet);
  TravellingState state;
  state.x_at_detection = start.model.nodes.x;
  // With joints, tets carry their joint state (bonded anywhere, not only by the joints that end
  // up held with them).
  // Decided alike on every rank (a rank may start with no tet, and receive some later), and so
  // is the branch below: both paths are collective.
  std::vector<std::int32_t> held = {!start.tet_joint_state.empty(),
                                    !start.model.tets.contact_faces.empty(), !start.joints.empty()};
  comm_.max_in_place(held);  // one reduction: any rank holds them
  has_joint_state_ = held[0] > 0;
  has_contact_faces_ = held[1] > 0;
  state.tet_joint_state = std::move(start.tet_joint_state);
  if (!has_joint_state_ && held[2] == 0) {
    local = std::move(start.model);
    append_halo(local, state, &start.tet_reach);
    local_state = std::move(state);
  } else {
    local = Model{};
    local.materials = start.model.materials;
    local.pieces = start.model.pieces;
    local.body_names = start.model.body_names;
    local.body_fixed = start.model.body_fixed;
    local.gravity = start.model.gravity;
    local.joint_laws = start.model.joint_laws;
    local.gid_offset = start.model.gid_offset;
    local.nodes.has_prescribed_velocity = start.model.nodes.has_prescribed_velocity;
    migrate(start.model, state, local, local_state, &start.joints, &start.tet_reach);
  }
  record_holders(local);
  report_.cycles = 1;
  update_report(local, false);
}

void Distribution::append_halo(Model& model, TravellingState& state,
                               const std::vector<double>* start_reach) {
  FDEM_VERIFY(model.joints.size() == 0 && state.pairs.empty() && !has_joint_state_,
              "append_halo: a model without joints or friction history");
  std::vector<char> send;
  std::vector<std::size_t> send_counts;
  pack_rows(model, state, destinations(model, false, start_reach), send, send_counts, nullptr);
  std::vector<char> receive = exchange_rows(send, send_counts);
  ParsedRows rows = parse_rows({&receive});
  FDEM_VERIFY(rows.joints.empty() && rows.pairs.empty(), "halo rows without joints");
  const auto by_gid = [](const auto& a, const auto& b) { return a.gid < b.gid; };
  const auto same_gid = [](const auto& a, const auto& b) { return a.gid == b.gid; };
  NodeArrays& nodes = model.nodes;
  TetArrays& tets = model.tets;

  // Nodes: the ones not held yet are ghosts, appended, then the ghost range sorted by gid.
  std::sort(rows.nodes.begin(), rows.nodes.end(), by_gid);
  rows.nodes.erase(std::unique(rows.nodes.begin(), rows.nodes.end(), same_gid), rows.nodes.end());
  rows.nodes.erase(std::remove_if(rows.nodes.begin(), rows.nodes.end(),
                                  [&](const NodeRow& r) { return nodes.find(r.gid) >= 0; }),
                   rows.nodes.end());
  const auto n_old = static_cast<std::size_t>(nodes.size());
  const std::size_t n_all = n_old + rows.nodes.size();
  const auto n_owned = static_cast<std::size_t>(nodes.n_owned);
  nodes.resize(local_count(n_all, "nodes"));
  resize_exact(node_owner_, n_all);
  resize_exact(node_first_tet_, n_all);
  for (const auto& field : travelling_node_fields) field.resize(state, n_all);
  for (std::size_t k = 0; k < rows.nodes.size(); ++k) {
    const NodeRow& r = rows.nodes[k];
    const std::size_t n = n_old + k;
    FDEM_VERIFY(r.owner != comm_.rank(), "a node owned here is held already");
    store_node_row(rows, r, n, nodes, node_owner_, node_first_tet_, state);
  }
  rows.nodes = std::vector<NodeRow>{};
  rows.node_values = std::vector<unsigned char>{};
  nodes.compact_references();
  std::vector<std::size_t> order(n_all - n_owned);
  std::iota(order.begin(), order.end(), n_owned);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return nodes.gid[a] < nodes.gid[b]; });
  std::vector<LocalIndex> moved_to(n_all - n_owned);  // old ghost index − n_owned → new index
  for (std::size_t i = 0; i < order.size(); ++i)
    moved_to[order[i] - n_owned] = static_cast<LocalIndex>(n_owned + i);
  const auto permute = [&](const auto& field, auto& values) {
    permute_tail(values, static_cast<std::size_t>(field.components), n_owned, order);
  };
  permute_tail(nodes.gid, 1, n_owned, order);
  for_each_field_array(node_fields, nodes, permute);
  for_each_field_array(travelling_node_fields, state, permute);
  permute_tail(node_owner_, 1, n_owned, order);
  permute_tail(node_first_tet_, 1, n_owned, order);
  for (LocalIndex& n : tets.nodes)
    if (static_cast<std::size_t>(n) >= n_owned) n = moved_to[static_cast<std::size_t>(n) - n_owned];

  // Tets: the block's tets are contiguous in gid; halo tets of lower blocks go before them.
  std::sort(rows.tets.begin(), rows.tets.end(), by_gid);
  const auto t_old = static_cast<std::size_t>(tets.size());
  const std::size_t t_all = t_old + rows.tets.size();
  local_count(t_all, "tetrahedra");
  const GlobalId block_first = t_old ? tets.gid[0] : 0;
  const auto lower = static_cast<std::size_t>(
      std::lower_bound(rows.tets.begin(), rows.tets.end(), block_first,
                       [](const TetRow& r, GlobalId g) { return r.gid < g; }) -
      rows.tets.begin());
  FDEM_VERIFY(tets.contact_group.size() == t_old && tets.owned.size() == t_old &&
                  tets.active.size() == t_old,
              "the block's tets carry their groups and roles");
  open_rows(tets.gid, 1, t_old, t_all, lower);
  open_rows(tets.nodes, 4, t_old, t_all, lower);
  for_each_field_array(tet_fields, tets, [&](const auto& field, auto& values) {
    open_rows(values, static_cast<std::size_t>(field.components), t_old, t_all, lower);
  });
  open_rows(tets.owned, 1, t_old, t_all, lower);
  open_rows(tets.active, 1, t_old, t_all, lower);
  open_rows(tet_owner_, 1, t_old, t_all, lower);
  for (std::size_t k = 0; k < rows.tets.size(); ++k) {
    const TetRow& r = rows.tets[k];
    const std::size_t t = k < lower ? k : t_old + k;
    FDEM_VERIFY(
        r.owner != comm_.rank() && (k < lower || t_old == 0 || r.gid > tets.gid[lower + t_old - 1]),
        "halo tets lie outside the block");
    const bool touches_owned = store_tet_row(rows, r, t, tets, tet_owner_, nodes, state);
    tets.owned[t] = 0;
    tets.active[t] = touches_owned;
  }
  rows.tets = std::vector<TetRow>{};
  rows.tet_values = std::vector<unsigned char>{};
  build_tet_force_order(tets, model.tet_force_order);
  build_exchange(model);
}

}  // namespace fdem
