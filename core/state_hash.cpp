#include "core/state_hash.hpp"

#include <algorithm>
#include <cstring>
#include <initializer_list>
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
// FNV-1a over (gid, the given 3-vectors) of nodes [0, count), visited in ascending gid.
std::uint64_t hash_in_gid_order(const NodeArrays& nodes, LocalIndex count,
                                std::initializer_list<const std::vector<double>*> fields) {
  std::vector<LocalIndex> order(static_cast<std::size_t>(count));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](LocalIndex a, LocalIndex b) { return nodes.gid[a] < nodes.gid[b]; });
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (LocalIndex n : order) {
    fnv_mix(h, &nodes.gid[n], sizeof(GlobalId));
    for (const std::vector<double>* field : fields)
      fnv_mix(h, field->data() + 3 * static_cast<std::size_t>(n), 3 * sizeof(double));
  }
  return h;
}
}  // namespace

std::uint64_t state_hash(const NodeArrays& nodes) {
  return hash_in_gid_order(nodes, nodes.n_owned, {&nodes.x, &nodes.v});
}

std::uint64_t reference_hash(const NodeArrays& nodes) {
  return hash_in_gid_order(nodes, nodes.size(), {&nodes.x0});
}

std::string hash_to_hex(std::uint64_t hash) {
  static const char* digits = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) s[i] = digits[hash & 0xf];
  return s;
}

}  // namespace fdem
