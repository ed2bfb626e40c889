// What the checkpoint writer (parallel/checkpoint.cpp) and reader (parallel/checkpoint_read.cpp)
// share: the format name, the header text that its checksum covers, and the contiguous gid blocks
// that rank r writes and reads (parallel/gid_blocks).  Internal to parallel/.
#pragma once

#include <hdf5.h>

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

// The checksum of the header (root counts, /run values and the field list).
inline std::uint64_t header_checksum(const std::string& serialized_header,
                                     const std::string& field_list) {
  return text_checksum(serialized_header + " f:" + field_list);
}

// Dataset shape of a column: [rows] for one component, else [rows][components].
inline hsize_t file_width(const CheckpointColumn& column) {
  return column.components == 1 ? 0 : column.components;
}

// Rank r writes (and reads) rows [begin(r), begin(r + 1)).
using fdem::GidBlocks;

}  // namespace fdem::checkpoint_format
