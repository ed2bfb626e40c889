// The per-step ghost exchange (parallel/distribution.hpp): which ghost nodes each neighbour
// sends, split-phase sends and receives of the halo fields (core/fields.hpp: positions and
// velocities), and the refresh of every
// ghost before a redistribution when the step's exchange is trimmed.
#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "core/fields.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

namespace {

struct HaloField {
  std::vector<double> NodeArrays::*member;
  std::size_t components;
};

// The node fields ghost copies refresh every step, in table order (doubles).
const std::vector<HaloField>& halo_fields() {
  static const std::vector<HaloField> fields = [] {
    std::vector<HaloField> out;
    for (const auto& field : node_fields)
      if (field.has(FieldUse::halo)) {
        FDEM_VERIFY(field.type() == ValueType::f64, "halo fields are doubles");
        out.push_back({std::get<Field<NodeArrays>::F64>(field.member),
                       static_cast<std::size_t>(field.components)});
      }
    return out;
  }();
  return fields;
}

std::size_t halo_doubles_per_node() {
  std::size_t width = 0;
  for (const HaloField& field : halo_fields()) width += field.components;
  return width;
}

}  // namespace

void Distribution::build_exchange(const Model& model) {
  const int ranks = comm_.size();
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  // What the step needs of the ghosts.  Without contact: the nodes of every tet that touches a
  // node of an owned tet (the active tets, and the tets around their nodes that the stable-step
  // guard weighs) and of both tets of a joint with an active tet.  With contact every held tet
  // may become a partner at the next detection, so every ghost travels.
  trimmed_ = buffer_ == 0.0;
  std::vector<std::uint8_t> needed(static_cast<std::size_t>(nodes.size()), trimmed_ ? 0 : 1);
  if (trimmed_) {
    std::vector<std::uint8_t> of_owned(needed.size(), 0);
    const auto node = [&](LocalIndex t, int c) {
      return tets.nodes[4 * static_cast<std::size_t>(t) + c];
    };
    const auto mark_tet = [&](LocalIndex t) {
      for (int c = 0; c < 4; ++c) needed[node(t, c)] = 1;
    };
    for (LocalIndex t = 0; t < tets.size(); ++t)
      if (tets.is_owned(t))
        for (int c = 0; c < 4; ++c) of_owned[node(t, c)] = 1;
    for (LocalIndex t = 0; t < tets.size(); ++t)
      for (int c = 0; c < 4; ++c)
        if (of_owned[node(t, c)]) {
          mark_tet(t);
          break;
        }
    for (LocalIndex j = 0; j < model.joints.size(); ++j) {
      const LocalIndex a = model.joints.tets[2 * j], b = model.joints.tets[2 * j + 1];
      if (tets.active[a] || tets.active[b]) {
        mark_tet(a);
        mark_tet(b);
      }
    }
  }
  // What this rank receives: its ghosts, from their owners (ghosts are in ascending gid), each
  // asked for with whether the step needs it.
  struct Ask {
    GlobalId gid;
    std::int64_t needed;
  };
  std::vector<std::vector<LocalIndex>> receive(static_cast<std::size_t>(ranks));
  std::vector<std::vector<Ask>> request(static_cast<std::size_t>(ranks));
  for (LocalIndex n = nodes.n_owned; n < nodes.size(); ++n) {
    const int owner = node_owner_[static_cast<std::size_t>(n)];
    FDEM_VERIFY(owner != comm_.rank(), "a ghost node is owned elsewhere");
    receive[owner].push_back(n);
    request[owner].push_back({nodes.gid[n], needed[n]});
  }
  std::vector<int> asker;  // the rank of each asked gid (in rank order)
  const std::vector<Ask> asked = comm_.exchange_sparse(request, &asker);
  std::unordered_map<GlobalId, LocalIndex> owned_index;
  owned_index.reserve(static_cast<std::size_t>(nodes.n_owned));
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) owned_index.emplace(nodes.gid[n], n);
  neighbours_.clear();
  all_ghosts_.clear();
  std::size_t next = 0;  // first asked gid of rank p
  for (int p = 0; p < ranks; ++p) {
    const std::size_t first = next;
    while (next < asked.size() && asker[next] == p) ++next;
    if (receive[p].empty() && next == first) continue;
    Neighbour all, step;
    all.rank = step.rank = p;
    all.receive = std::move(receive[p]);
    for (LocalIndex n : all.receive)
      if (needed[n]) step.receive.push_back(n);
    for (std::size_t i = first; i < next; ++i) {
      const auto it = owned_index.find(asked[i].gid);
      FDEM_VERIFY(it != owned_index.end(), "a rank asks for a node this rank owns");
      all.send.push_back(it->second);
      if (asked[i].needed) step.send.push_back(it->second);
    }
    const std::size_t width = halo_doubles_per_node();
    for (Neighbour* nb : {&all, &step}) {
      nb->send_buffer.resize(width * nb->send.size());
      nb->receive_buffer.resize(width * nb->receive.size());
    }
    if (!step.send.empty() || !step.receive.empty()) neighbours_.push_back(std::move(step));
    if (trimmed_) all_ghosts_.push_back(std::move(all));
  }
}

void Distribution::start_halo_exchange(const NodeArrays& nodes) {
  start_exchange(neighbours_, nodes);
}

void Distribution::finish_halo_exchange(NodeArrays& nodes) {
  finish_exchange(neighbours_, nodes);
}

void Distribution::start_exchange(std::vector<Neighbour>& plan, const NodeArrays& nodes) {
  requests_.clear();
  constexpr int tag = 8;  // stage 8 of the step
  for (Neighbour& nb : plan)
    if (!nb.receive.empty()) {
      requests_.emplace_back();
      // A few doubles per node: fits an int, local counts being at most max_local_entries.
      MPI_Irecv(nb.receive_buffer.data(), detail::checked_count(nb.receive_buffer.size(), 1),
                MPI_DOUBLE, nb.rank, tag, comm_.handle(), &requests_.back());
    }
  for (Neighbour& nb : plan)
    if (!nb.send.empty()) {
      double* out = nb.send_buffer.data();
      const std::vector<HaloField>& fields = halo_fields();
      for (LocalIndex n : nb.send)
        for (const HaloField& field : fields)
          out = std::copy_n((nodes.*field.member).data() + field.components * std::size_t(n),
                            field.components, out);
      requests_.emplace_back();
      MPI_Isend(nb.send_buffer.data(), detail::checked_count(nb.send_buffer.size(), 1), MPI_DOUBLE,
                nb.rank, tag, comm_.handle(), &requests_.back());
    }
}

void Distribution::finish_exchange(const std::vector<Neighbour>& plan, NodeArrays& nodes) {
  if (!requests_.empty())
    MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  requests_.clear();
  for (const Neighbour& nb : plan) {
    const double* in = nb.receive_buffer.data();
    const std::vector<HaloField>& fields = halo_fields();
    for (LocalIndex n : nb.receive)
      for (const HaloField& field : fields) {
        std::copy_n(in, field.components,
                    (nodes.*field.member).data() + field.components * std::size_t(n));
        in += field.components;
      }
  }
}

void Distribution::refresh_all_ghosts(NodeArrays& nodes) {
  if (!trimmed_) return;  // the step's exchange carries every ghost already
  start_exchange(all_ghosts_, nodes);
  finish_exchange(all_ghosts_, nodes);
}

}  // namespace fdem
