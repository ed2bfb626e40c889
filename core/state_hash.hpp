// Bitwise fingerprint of the nodal state (positions and velocities ordered by global id): the same
// scene gives the same hash on any number of ranks and after a restart.
#pragma once

#include <cstdint>
#include <string>

#include "core/model.hpp"

namespace fdem {

// FNV-1a over (gid, x, v) of the owned nodes, visited in ascending global id.
std::uint64_t state_hash(const NodeArrays& nodes);
std::string hash_to_hex(std::uint64_t hash);
// FNV-1a over (gid, x0) of all nodes in ascending gid: identifies the scene a checkpoint belongs
// to.
std::uint64_t reference_hash(const NodeArrays& nodes);

}  // namespace fdem
