// Hashes that pick directory ranks in the distributed start-up (parallel/distributed_joints,
// parallel/boundary_matching): every rank computes the same rank for the same key.
#pragma once

#include <cstdint>
#include <initializer_list>

namespace fdem {

inline std::uint64_t directory_mix(std::uint64_t h) {  // splitmix64's finaliser
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebULL;
  return h ^ (h >> 31);
}

inline std::uint64_t directory_hash(std::initializer_list<std::int64_t> values) {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL;
  for (std::int64_t v : values) h = directory_mix(h ^ static_cast<std::uint64_t>(v));
  return h;
}

// The rank (of `ranks`) that answers for a key.
inline int directory_rank(std::initializer_list<std::int64_t> values, int ranks) {
  return static_cast<int>(directory_hash(values) % static_cast<std::uint64_t>(ranks));
}

}  // namespace fdem
