// What the checkpoint writer (parallel/checkpoint.cpp) and reader (parallel/checkpoint_read.cpp)
// share: the format name, the header text that its checksum covers, and the contiguous gid blocks
// that rank r writes and reads (parallel/gid_blocks).  Internal to parallel/.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "core/types.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/gid_blocks.hpp"

namespace fdem::checkpoint_format {

constexpr const char* format_name = "fdem-checkpoint";

// The header as text: counts, reference hash, and every run value bit for bit.
inline std::string serialized(const CheckpointHeader& header) {
  std::ostringstream out;
  out << header.n_nodes << ' ' << header.n_tets << ' ' << header.n_joints << ' '
      << header.reference_hash;
  for (const auto& [name, value] : header.doubles) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    out << " d:" << name.size() << ':' << name << '=' << bits;
  }
  for (const auto& [name, value] : header.integers)
    out << " i:" << name.size() << ':' << name << '=' << value;
  return out.str();
}

// The checksum of the header (root counts and /run values).
inline std::uint64_t header_checksum(const std::string& serialized_header,
                                     std::int64_t history_bytes) {
  return text_checksum(serialized_header + " h:" + std::to_string(history_bytes));
}

// Rank r writes (and reads) rows [begin(r), begin(r + 1)).
using fdem::GidBlocks;

}  // namespace fdem::checkpoint_format
