// A rank's block of the distributed start-up against the serial builder's whole model, bit for
// bit (tests/mpi/test_distributed_build.cpp, test_file_mesh.cpp).  CHECK only: a rank leaving a
// test case early would skip its collectives.
#pragma once

#include <catch2/catch.hpp>
#include <cstring>

#include "core/model.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distributed_build.hpp"
#include "parallel/piece_directory.hpp"

namespace fdem::testing {

inline bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// Collective (sums over the ranks).  `serial`: build_model's model of the same scene (gid =
// gid_offset + index, the same offset).
inline void check_block_is_serial_model(const DistributedModel& block, const Model& serial,
                                        const Communicator& comm) {
  const Model& local = block.model;
  const GlobalId offset = serial.gid_offset;
  CHECK(local.gid_offset == offset);
  CHECK(block.n_tets == serial.tets.size());
  CHECK(block.n_nodes == serial.nodes.size());
  CHECK(comm.sum(std::int64_t{local.tets.size()}) == serial.tets.size());
  CHECK(comm.sum(std::int64_t{local.nodes.n_owned}) == serial.nodes.size());
  // Blocks are contiguous gid ranges, in rank order.
  CHECK(local.tets.size() == block.tet_block[comm.rank() + 1] - block.tet_block[comm.rank()]);

  long tet_mismatches = 0, node_mismatches = 0;
  for (LocalIndex t = 0; t < local.tets.size(); ++t) {
    const auto g = static_cast<std::size_t>(local.tets.gid[t] - offset);
    if (local.tets.gid[t] < offset || g >= static_cast<std::size_t>(serial.tets.size())) {
      ++tet_mismatches;
      continue;
    }
    bool same = local.tets.gid[t] == serial.tets.gid[g] &&
                local.tets.material[t] == serial.tets.material[g] &&
                local.tets.piece[t] == serial.tets.piece[g] &&
                local.tets.group_of(static_cast<LocalIndex>(t)) ==
                    serial.tets.group_of(static_cast<LocalIndex>(g)) &&
                same_bits(local.tets.volume0[t], serial.tets.volume0[g]) &&
                same_bits(local.tets.viscosity[t], serial.tets.viscosity[g]);
    for (int k = 0; k < 9; ++k)
      same = same && same_bits(local.tets.dm_inv[9 * t + k], serial.tets.dm_inv[9 * g + k]);
    for (int c = 0; c < 4; ++c)
      same = same && local.nodes.gid[local.tets.nodes[4 * t + c]] ==
                         serial.nodes.gid[serial.tets.nodes[4 * g + c]];
    tet_mismatches += !same;
  }
  CHECK(local.nodes.has_prescribed_velocity == serial.nodes.has_prescribed_velocity);
  for (LocalIndex n = 0; n < local.nodes.size(); ++n) {
    const auto g = static_cast<std::size_t>(local.nodes.gid[n] - offset);
    if (local.nodes.gid[n] < offset || g >= static_cast<std::size_t>(serial.nodes.size())) {
      ++node_mismatches;
      continue;
    }
    bool same = local.nodes.gid[n] == serial.nodes.gid[g] &&
                local.nodes.piece[n] == serial.nodes.piece[g] &&
                same_bits(local.nodes.mass[n], serial.nodes.mass[g]) &&
                local.nodes.constrained[n] == serial.nodes.constrained[g];
    for (int k = 0; k < 3; ++k)
      same = same && same_bits(local.nodes.x0(n)[k], serial.nodes.x0(g)[k]) &&
             same_bits(local.nodes.x[3 * n + k], serial.nodes.x[3 * g + k]) &&
             same_bits(local.nodes.v[3 * n + k], serial.nodes.v[3 * g + k]) &&
             same_bits(local.nodes.prescribed_velocity_at(3 * n + k),
                       serial.nodes.prescribed_velocity_at(3 * g + k));
    // Owned nodes: their first tet is in this block; the owner table says so.
    same = same && (n < local.nodes.n_owned) == (block.node_owner[n] == comm.rank()) &&
           block.node_first_tet[n] >= offset;
    node_mismatches += !same;
  }
  CHECK(tet_mismatches == 0);
  CHECK(node_mismatches == 0);
  // Pieces: the same numbering; masses and centroids kept for the directory block only.
  REQUIRE(local.pieces.size() == serial.pieces.size());
  long piece_mismatches = 0;
  for (std::int32_t p = 0; p < static_cast<std::int32_t>(serial.pieces.size()); ++p)
    piece_mismatches += local.pieces.body_of(p) != serial.pieces.body_of(p) ||
                        local.pieces.index_in_body(p) != serial.pieces.index_in_body(p);
  const PieceBlock directory = piece_directory_block(local.pieces, comm);
  CHECK(local.pieces.kept().size() == static_cast<std::size_t>(directory.end - directory.begin));
  for (const std::int32_t p : local.pieces.kept()) {
    bool same = p >= directory.begin && p < directory.end &&
                local.pieces[p].body == serial.pieces[p].body &&
                local.pieces[p].index_in_body == serial.pieces[p].index_in_body &&
                same_bits(local.pieces[p].mass, serial.pieces[p].mass);
    for (int k = 0; k < 3; ++k)
      same = same && same_bits(local.pieces[p].centroid0[k], serial.pieces[p].centroid0[k]);
    piece_mismatches += !same;
  }
  CHECK(piece_mismatches == 0);
  // Every rank holds the same whole-model ranks of the blocks, and they cover all tets.
  CHECK(block.tet_block.front() == offset);
  CHECK(block.tet_block.back() == offset + serial.tets.size());
}

}  // namespace fdem::testing
