// What the checkpoint writer (parallel/checkpoint.cpp) and reader (parallel/checkpoint_read.cpp)
// share: the format name, the header text that its checksum covers, and the contiguous gid blocks
// that rank r writes and reads.  Internal to parallel/.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>

#include "core/types.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_checksum.hpp"

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

// n rows cut into `ranks` contiguous blocks, the first n % ranks of them one row longer: rank r
// writes (and reads) rows [begin(r), begin(r + 1)).
struct GidBlocks {
  std::int64_t n = 0;
  int ranks = 1;

  std::int64_t begin(std::int64_t r) const {
    return r * (n / ranks) + std::min<std::int64_t>(r, n % ranks);
  }
  std::int64_t count(int r) const { return begin(r + 1) - begin(r); }
  // The rank whose block holds row g (0 <= g < n).
  int owner(GlobalId g) const {
    const std::int64_t base = n / ranks, extra = n % ranks, long_end = extra * (base + 1);
    return static_cast<int>(g < long_end ? g / (base + 1) : extra + (g - long_end) / base);
  }
};

}  // namespace fdem::checkpoint_format
