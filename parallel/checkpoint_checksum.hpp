// Checksums of checkpoint datasets (parallel/checkpoint.cpp).  A dataset's checksum is the sum
// (mod 2^64) over its rows of a 64-bit hash of (dataset name, row index, the row's values as
// little-endian bytes): any rank can add up the rows it holds, the ranks' sums add up to the
// whole, and a changed, swapped or zeroed row changes the result (but for a 2^-64 chance).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace fdem {

namespace checksum_detail {

constexpr std::uint64_t fnv_offset = 1469598103934665603ull;
constexpr std::uint64_t fnv_prime = 1099511628211ull;

// splitmix64's finaliser: every input bit affects every output bit.
inline std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

inline std::uint64_t text_hash(const std::string& text) {
  std::uint64_t h = fnv_offset;
  for (unsigned char c : text) h = (h ^ c) * fnv_prime;
  return h;
}

// FNV-1a over `value`'s bytes, least significant first (the file's little-endian order whatever
// the host's).
template <class T>
std::uint64_t add_value(std::uint64_t h, T value) {
  static_assert(sizeof(T) <= 8, "checksummed values are at most 8 bytes");
  std::uint64_t bits = 0;
  if constexpr (sizeof(T) == 8) {
    std::memcpy(&bits, &value, 8);
  } else if constexpr (sizeof(T) == 4) {
    std::uint32_t b = 0;
    std::memcpy(&b, &value, 4);
    bits = b;
  } else {
    static_assert(sizeof(T) == 1, "checksummed values are 1, 4 or 8 bytes");
    std::uint8_t b = 0;
    std::memcpy(&b, &value, 1);
    bits = b;
  }
  for (std::size_t k = 0; k < sizeof(T); ++k) h = (h ^ ((bits >> (8 * k)) & 0xffu)) * fnv_prime;
  return h;
}

}  // namespace checksum_detail

// The sum of the terms of the rows first_row, first_row + 1, ... held in `values` (`width`
// values per row; 0 means 1) of the dataset `name`.
template <class T>
std::uint64_t rows_checksum(const std::string& name, const std::vector<T>& values,
                            std::size_t width, std::uint64_t first_row) {
  using namespace checksum_detail;
  const std::size_t w = width == 0 ? 1 : width;
  const std::uint64_t seed = text_hash(name);
  std::uint64_t sum = 0;
  for (std::size_t r = 0; r * w < values.size(); ++r) {
    std::uint64_t h = seed ^ mix(first_row + r + 0x9e3779b97f4a7c15ull);
    for (std::size_t k = 0; k < w && r * w + k < values.size(); ++k)
      h = add_value(h, values[r * w + k]);
    sum += mix(h);
  }
  return sum;
}

// Hash of a text (the checkpoint header, serialized).
inline std::uint64_t text_checksum(const std::string& text) {
  return checksum_detail::mix(checksum_detail::text_hash(text));
}

}  // namespace fdem
