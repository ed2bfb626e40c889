// Bitwise fingerprint of the nodal state (positions and velocities with their global ids): the same
// scene gives the same hash on any number of ranks and after a restart.  The fingerprint is a sum
// modulo 2^64 of one 64-bit hash per node, so each rank hashes the nodes it owns and one integer
// sum-reduction combines them (parallel/distribution: global_state_hash) — no gather.
#pragma once

#include <cstdint>
#include <string>

#include "core/model.hpp"

namespace fdem {

// Σ mix(FNV-1a(gid − gid_offset, x, v)) over the owned nodes (mod 2^64).  Hashing the node's
// index rather than its gid makes the hash the same for any Model::gid_offset (the offset is a
// testing aid: the same run with gids above 2^32 must give the same hash).
std::uint64_t state_hash(const NodeArrays& nodes, GlobalId gid_offset);
std::string hash_to_hex(std::uint64_t hash);
// Σ mix(FNV-1a(gid − gid_offset, x0)) over the owned nodes: with the sum over ranks, identifies
// the scene a checkpoint belongs to.
std::uint64_t reference_hash(const NodeArrays& nodes, GlobalId gid_offset);

// The joints' strengths as drawn (core/joint_strength): Σ mix(FNV-1a(gid − gid_offset, f_t, c))
// over the joints whose tet A this rank owns, f_t and c (Pa) those of the joint's law.  Summed
// over ranks it is the same on any rank count exactly when every joint got the same strengths.
std::uint64_t joint_strength_hash(const Model& model);

}  // namespace fdem
