#include "parallel/distributed_build.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/joint_placement.hpp"
#include "core/tet_kernels.hpp"
#include "parallel/distributed_build_steps.hpp"
#include "parallel/distributed_joints.hpp"
#include "parallel/piece_directory.hpp"

namespace fdem {

using namespace distributed_build_steps;

DistributedModel build_distributed_model(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                         const Communicator& comm) {
  FDEM_VERIFY(chunks.size() == scene.bodies.size(), "one chunk plan per body");
  const int ranks = comm.size(), me = comm.rank();
  DistributedModel out;
  Model& model = out.model;
  model = model_frame(scene);
  std::vector<std::int64_t> node_base(chunks.size() + 1, 0);
  std::vector<std::int32_t> piece_base(chunks.size() + 1, 0);
  std::vector<std::int64_t> body_tets(chunks.size(), 0);
  for (std::size_t b = 0; b < chunks.size(); ++b) {
    node_base[b + 1] = node_base[b] + chunks[b].n_nodes;
    piece_base[b + 1] = piece_base[b] + chunks[b].n_pieces;
    model.pieces.add_body(chunks[b].n_pieces);
    for (std::int64_t n : chunks[b].chunk_tets) body_tets[b] += n;
    out.n_tets += body_tets[b];
  }
  NodeKeys keys;
  keys.split_start = node_base.back();
  std::int64_t next_split = keys.split_start;
  for (std::size_t b = 0; b < chunks.size(); ++b) {
    const bool split = scene.bodies[b].joints == JointPlacement::all;
    keys.split_base.push_back(split ? next_split : -1);
    if (split) next_split += 4 * body_tets[b];
  }

  // Steps 1–3: records generated here, sorted into equal blocks of gids.
  Vec3 lo, hi;  // box of all nodes (m)
  std::vector<TetRecord> records = generate_records(
      scene, chunks, node_base, piece_base,
      mul_div(out.n_tets, me + 1, ranks) - mul_div(out.n_tets, me, ranks), comm, &lo, &hi);
  out.tet_block.resize(static_cast<std::size_t>(ranks) + 1);
  for (int r = 0; r <= ranks; ++r)
    out.tet_block[r] = model.gid_offset + mul_div(out.n_tets, r, ranks);
  records = sort_into_blocks(std::move(records), out.tet_block, comm);
  const GlobalId first_tet = out.tet_block[me];
  FDEM_VERIFY(static_cast<GlobalId>(records.size()) == out.tet_block[me + 1] - first_tet,
              "a rank receives its block of tets");

  // Step 4: node numbers; local nodes = owned (first used here) then the others, each by gid.
  const std::vector<NodeNumber> numbers =
      number_nodes(records, first_tet, out.tet_block, keys, NodeDirectory(records, lo, hi, comm),
                   comm, &out.n_nodes);
  const auto number_of = [&](std::int64_t mesh_node) -> const NodeNumber& {
    const auto it =
        std::lower_bound(numbers.begin(), numbers.end(), mesh_node,
                         [](const NodeNumber& a, std::int64_t m) { return a.mesh_node < m; });
    FDEM_VERIFY(it != numbers.end() && it->mesh_node == mesh_node, "a used node has a number");
    return *it;
  };
  struct LocalNode {
    GlobalId gid, first_tet;
    const double* x;
    std::int32_t piece;
  };
  // One entry per node used here (`numbers` holds each once, by mesh node): its position and
  // piece from the first corner that uses it.
  std::vector<LocalNode> local_nodes(numbers.size(), LocalNode{0, 0, nullptr, 0});
  for (const TetRecord& r : records)
    for (int c = 0; c < 4; ++c) {
      const NodeNumber& n = number_of(keys.key(r, c));
      LocalNode& l = local_nodes[static_cast<std::size_t>(&n - numbers.data())];
      if (!l.x) l = {n.gid, n.first_tet, &r.x[3 * c], r.piece};
    }
  for (const LocalNode& l : local_nodes) FDEM_VERIFY(l.x, "every numbered node is used here");
  const auto owned_here = [&](const LocalNode& n) {
    return n.first_tet >= first_tet && n.first_tet < out.tet_block[me + 1];
  };
  std::sort(local_nodes.begin(), local_nodes.end(), [&](const LocalNode& a, const LocalNode& b) {
    const bool oa = owned_here(a), ob = owned_here(b);
    return oa != ob ? oa : a.gid < b.gid;
  });
  NodeArrays& nodes = model.nodes;
  const LocalIndex n_local = local_count(local_nodes.size(), "nodes");
  nodes.has_prescribed_velocity = scene.prescribes_velocities();
  nodes.resize(n_local);
  nodes.reference_positions.clear();
  nodes.n_owned = 0;
  out.node_first_tet.resize(static_cast<std::size_t>(n_local));
  out.node_owner.resize(static_cast<std::size_t>(n_local));
  for (LocalIndex n = 0; n < n_local; ++n) {
    const LocalNode& l = local_nodes[n];
    nodes.gid[n] = l.gid;
    nodes.add_reference(n, l.x);
    std::copy_n(l.x, 3, nodes.x.data() + 3 * static_cast<std::size_t>(n));
    nodes.piece[n] = l.piece;
    out.node_first_tet[n] = l.first_tet;
    out.node_owner[n] = block_owner(out.tet_block, l.first_tet);
    if (out.node_owner[n] == me) nodes.n_owned = n + 1;
  }
  nodes.compact_references();
  std::fill(nodes.v.begin(), nodes.v.end(), 0.0);
  std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  std::fill(nodes.mass.begin(), nodes.mass.end(), 0.0);
  std::fill(nodes.constrained.begin(), nodes.constrained.end(), 0);
  std::fill(nodes.prescribed_velocity.begin(), nodes.prescribed_velocity.end(), 0.0);
  const auto local_node = [&](GlobalId gid) {
    const LocalIndex n = nodes.find(gid);
    FDEM_VERIFY(n >= 0, "a node of a local tet is local");
    return n;
  };

  // The nodes hold the positions now: the records shrink to their links before the tet arrays
  // are made (the start-up's peak would otherwise hold both).
  std::vector<TetLinks> links(records.size());
  for (std::size_t t = 0; t < records.size(); ++t) {
    const TetRecord& r = records[t];
    links[t] = {r.body, r.piece, r.mesh_tet, {r.node[0], r.node[1], r.node[2], r.node[3]}};
  }
  records = std::vector<TetRecord>{};
  local_nodes = std::vector<LocalNode>{};  // pointed into the records

  // Tets: reference shapes, viscosities; node masses summed at the owners in tet-gid order, with
  // the largest extent among each node's tets (the reach of the first halo).
  TetArrays& tets = model.tets;
  const LocalIndex n_tets = local_count(links.size(), "tetrahedra");
  tets.resize(n_tets);
  tets.n_owned = n_tets;
  tets.contact_group.resize(n_tets);
  tets.owned.assign(n_tets, 1);
  tets.active.assign(n_tets, 1);
  // A node owned here is first used here, so no tet of a lower rank uses it: its mass is the sum
  // of this block's quarters in gid order (added right away), then those of higher ranks' tets
  // (sent here, added after in gid order) — the serial builder's order.  Only the quarters for
  // nodes owned elsewhere travel.
  std::vector<double> tet_extent(static_cast<std::size_t>(n_tets));
  std::vector<FaceTet> face_tets;  // tets of bodies that joints concern
  std::vector<char> has_faces(chunks.size());
  for (std::size_t b = 0; b < chunks.size(); ++b) has_faces[b] = body_has_faces(scene, b);
  std::vector<double> node_extent(static_cast<std::size_t>(n_local), 0.0);
  std::vector<std::vector<MassPart>> parts(static_cast<std::size_t>(ranks));
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetLinks& r = links[t];
    const std::int32_t material = scene.bodies[r.body].material;
    tets.gid[t] = first_tet + t;
    tets.material[t] = material;
    tets.piece[t] = tets.contact_group[t] = r.piece;
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = local_node(number_of(keys.key(r, c)).gid);
      tets.nodes[4 * t + c] = n;
      X[c] = nodes.x0(n);
    }
    const TetSetup setup = setup_tet(X, model.materials[material]);
    Eigen::Map<Mat3>(tets.dm_inv.data() + 9 * static_cast<std::size_t>(t)) = setup.dm_inv;
    tets.volume0[t] = setup.volume;
    tets.viscosity[t] = setup.viscosity;
    Vec3 box_lo = X[0], box_hi = X[0];
    for (int c = 1; c < 4; ++c) {
      box_lo = box_lo.cwiseMin(X[c]);
      box_hi = box_hi.cwiseMax(X[c]);
    }
    tet_extent[static_cast<std::size_t>(t)] = (box_hi - box_lo).maxCoeff();
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      if (n < nodes.n_owned) {
        nodes.mass[n] += 0.25 * setup.mass;
        node_extent[static_cast<std::size_t>(n)] = std::max(
            node_extent[static_cast<std::size_t>(n)], tet_extent[static_cast<std::size_t>(t)]);
      } else {
        parts[static_cast<std::size_t>(out.node_owner[n])].push_back(
            {nodes.gid[n], tets.gid[t], 0.25 * setup.mass,
             tet_extent[static_cast<std::size_t>(t)]});
      }
    }
    if (has_faces[static_cast<std::size_t>(r.body)]) {
      FaceTet f{t, r.body, {}};
      for (int c = 0; c < 4; ++c) f.mesh_node[c] = r.node[c] - node_base[r.body];
      face_tets.push_back(f);
    }
  }
  // Contact groups: a piece, or in a `joints: all` body each tet its own, numbered after the
  // pieces in gid order (as build_model numbers them).
  {
    std::int64_t split = 0;
    for (const TetLinks& r : links) split += keys.split(r);
    const std::vector<std::int64_t> counts = comm.allgather(split);
    std::int64_t next = static_cast<std::int64_t>(model.pieces.size()) +
                        std::accumulate(counts.begin(), counts.begin() + me, std::int64_t{0});
    FDEM_VERIFY(static_cast<std::int64_t>(model.pieces.size()) +
                        std::accumulate(counts.begin(), counts.end(), std::int64_t{0}) <=
                    std::numeric_limits<std::int32_t>::max(),
                "contact groups fit 32 bits");
    for (LocalIndex t = 0; t < n_tets; ++t)
      if (keys.split(links[t])) tets.contact_group[t] = static_cast<std::int32_t>(next++);
  }
  links = std::vector<TetLinks>{};
  std::vector<MassPart> arrived = comm.exchange(parts);
  parts.clear();
  std::sort(arrived.begin(), arrived.end(), [](const MassPart& a, const MassPart& b) {
    return a.node != b.node ? a.node < b.node : a.tet < b.tet;
  });
  for (const MassPart& p : arrived) {
    FDEM_VERIFY(p.tet >= out.tet_block[me + 1], "mass quarters arrive from higher blocks");
    const LocalIndex n = local_node(p.node);
    nodes.mass[n] += p.mass;
    node_extent[static_cast<std::size_t>(n)] =
        std::max(node_extent[static_cast<std::size_t>(n)], p.extent);
  }
  release(arrived);
  // The other local nodes ask their owners for the mass and extent.
  std::vector<std::vector<GlobalId>> asks(static_cast<std::size_t>(ranks));
  for (LocalIndex n = nodes.n_owned; n < n_local; ++n)
    asks[static_cast<std::size_t>(out.node_owner[n])].push_back(nodes.gid[n]);
  std::vector<int> asker;
  const std::vector<GlobalId> asked = comm.exchange(asks, &asker);
  std::vector<std::vector<NodeMass>> answers(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < asked.size(); ++i) {
    const LocalIndex n = local_node(asked[i]);
    answers[static_cast<std::size_t>(asker[i])].push_back(
        {asked[i], nodes.mass[n], node_extent[static_cast<std::size_t>(n)]});
  }
  for (const NodeMass& m : comm.exchange(answers)) {
    const LocalIndex n = local_node(m.node);
    nodes.mass[n] = m.mass;
    node_extent[static_cast<std::size_t>(n)] = m.extent;
  }

  // Joints (parallel/distributed_joints; every rank knows from the scene whether there are any),
  // and the reach of each tet over the whole model.
  BlockJoints joints;
  if (std::find(has_faces.begin(), has_faces.end(), 1) != has_faces.end()) {
    std::vector<std::string> sources;
    for (const BodyChunks& body : chunks) sources.push_back(body.source);
    joints = place_block_joints(scene, sources, model, tet_extent, face_tets, out.tet_block,
                                matching_tolerance(hi - lo), comm);
  }
  release(face_tets);
  out.joints = std::move(joints.joints);
  out.n_joints = joints.n_joints;
  model.joint_laws = std::move(joints.laws);
  if (out.n_joints > 0) out.tet_joint_state = std::move(joints.bonded);
  out.tet_reach = std::move(tet_extent);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    double& reach = out.tet_reach[static_cast<std::size_t>(t)];
    if (!joints.partner_extent.empty())
      reach = std::max(reach, joints.partner_extent[static_cast<std::size_t>(t)]);
    for (int c = 0; c < 4; ++c)
      reach = std::max(reach, node_extent[static_cast<std::size_t>(tets.nodes[4 * t + c])]);
  }

  // Pieces (kept at their directory ranks), velocities, constraints, force order.
  sum_pieces_by_directory(model, comm);
  set_dashpot_masses(model);
  set_initial_velocities(scene, model);
  keep_directory_block(model.pieces, comm);
  build_tet_force_order(tets, model.tet_force_order);
  apply_constraints(scene, model);
  return out;
}

double distributed_nth_value(const std::vector<double>& values, std::int64_t k,
                             const Communicator& comm) {
  // Non-negative doubles order as their bit patterns: find the smallest pattern v with more than
  // k values ≤ v.
  std::vector<std::uint64_t> bits(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    FDEM_VERIFY(values[i] >= 0.0, "distributed_nth_value takes non-negative values");
    std::memcpy(&bits[i], &values[i], sizeof(double));
  }
  std::uint64_t lo = 0, hi = std::numeric_limits<std::uint64_t>::max() >> 1;  // (lo, hi]
  while (lo < hi) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    std::int64_t count = 0;
    for (std::uint64_t b : bits) count += b <= mid;
    if (comm.sum(count) > k)
      hi = mid;
    else
      lo = mid + 1;
  }
  double out;
  std::memcpy(&out, &lo, sizeof(double));
  return out;
}

}  // namespace fdem
