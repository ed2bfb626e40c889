#include "core/state_hash.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <vector>

namespace fdem {

namespace {
inline void fnv_mix(std::uint64_t& h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
}
}  // namespace

std::uint64_t state_hash(const NodeArrays& nodes) {
  std::vector<LocalIndex> order(nodes.n_owned);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](LocalIndex a, LocalIndex b) { return nodes.gid[a] < nodes.gid[b]; });
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (LocalIndex n : order) {
    fnv_mix(h, &nodes.gid[n], sizeof(GlobalId));
    fnv_mix(h, &nodes.x[3 * n], 3 * sizeof(double));
    fnv_mix(h, &nodes.v[3 * n], 3 * sizeof(double));
  }
  return h;
}

std::uint64_t reference_hash(const NodeArrays& nodes) {
  std::vector<LocalIndex> order(nodes.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](LocalIndex a, LocalIndex b) { return nodes.gid[a] < nodes.gid[b]; });
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (LocalIndex n : order) {
    fnv_mix(h, &nodes.gid[n], sizeof(GlobalId));
    fnv_mix(h, &nodes.x0[3 * n], 3 * sizeof(double));
  }
  return h;
}

std::string hash_to_hex(std::uint64_t hash) {
  static const char* digits = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) s[i] = digits[hash & 0xf];
  return s;
}

}  // namespace fdem
