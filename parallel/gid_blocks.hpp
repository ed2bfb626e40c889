// n ids cut into `ranks` contiguous blocks, the first n % ranks of them one longer: rank r holds
// ids [begin(r), begin(r + 1)).  Checkpoint rows are written and read by these blocks, and a
// piece's data lives at the rank whose block holds its id (parallel/piece_directory).
#pragma once

#include <algorithm>
#include <cstdint>

#include "core/types.hpp"

namespace fdem {

struct GidBlocks {
  std::int64_t n = 0;
  int ranks = 1;

  std::int64_t begin(std::int64_t r) const {
    return r * (n / ranks) + std::min<std::int64_t>(r, n % ranks);
  }
  std::int64_t count(int r) const { return begin(r + 1) - begin(r); }
  // The rank whose block holds id g (0 <= g < n).
  int owner(GlobalId g) const {
    const std::int64_t base = n / ranks, extra = n % ranks, long_end = extra * (base + 1);
    return static_cast<int>(g < long_end ? g / (base + 1) : extra + (g - long_end) / base);
  }
};

}  // namespace fdem
