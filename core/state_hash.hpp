// Bitwise fingerprint of the nodal state (positions and velocities with their global ids): the same
// scene gives the same hash on any number of ranks and after a restart.  The fingerprint is a sum
// modulo 2^64 of one 64-bit hash per node, so each rank hashes the nodes it owns and one integer
// sum-reduction combines them (parallel/distribution: global_state_hash) — no gather.
#pragma once

#include <cstdint>
#include <string>

#include "core/model.hpp"

namespace fdem {

// Σ mix(FNV-1a(gid, x, v)) over the owned nodes (mod 2^64).
std::uint64_t state_hash(const NodeArrays& nodes);
std::string hash_to_hex(std::uint64_t hash);
// Σ mix(FNV-1a(gid, x0)) over the owned nodes: with the sum over ranks, identifies the scene a
// checkpoint belongs to.
std::uint64_t reference_hash(const NodeArrays& nodes);

}  // namespace fdem
