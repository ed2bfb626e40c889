#include "core/state_hash.hpp"

#include <cstring>
#include <vector>

#include "core/error.hpp"
#include "core/fields.hpp"

namespace fdem {

namespace {
inline void fnv_mix(std::uint64_t& h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
}
// splitmix64 finaliser: every input bit reaches every output bit before the sum.
inline std::uint64_t finish(std::uint64_t h) {
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ULL;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebULL;
  return h ^ (h >> 31);
}
}  // namespace

std::uint64_t state_hash(const NodeArrays& nodes, GlobalId gid_offset) {
  // The hashed fields, in table order (x, v): 3 doubles each (checked once).
  static const std::vector<std::vector<double> NodeArrays::*> hashed = [] {
    std::vector<std::vector<double> NodeArrays::*> members;
    for (const auto& field : node_fields)
      if (field.has(FieldUse::hash)) {
        FDEM_VERIFY(field.type() == ValueType::f64 && field.components == 3,
                    "hashed node fields are 3-vectors of doubles");
        members.push_back(std::get<Field<NodeArrays>::F64>(field.member));
      }
    return members;
  }();
  std::uint64_t sum = 0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    const GlobalId index = nodes.gid[n] - gid_offset;
    fnv_mix(h, &index, sizeof(GlobalId));
    for (const auto member : hashed)
      fnv_mix(h, (nodes.*member).data() + 3 * static_cast<std::size_t>(n), 3 * sizeof(double));
    sum += finish(h);
  }
  return sum;
}

std::uint64_t reference_hash(const NodeArrays& nodes, GlobalId gid_offset) {
  // Σ over owned nodes of mix(FNV-1a of (gid − gid_offset, x0)), mod 2^64: a sum of per-node
  // fingerprints depends neither on the order of the nodes nor on how ranks split them.
  std::uint64_t sum = 0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    const GlobalId index = nodes.gid[n] - gid_offset;
    fnv_mix(h, &index, sizeof(GlobalId));
    fnv_mix(h, nodes.x0(n).data(), 3 * sizeof(double));
    sum += finish(h);
  }
  return sum;
}

std::uint64_t joint_strength_hash(const Model& model) {
  const JointArrays& joints = model.joints;
  std::uint64_t sum = 0;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (!model.tets.is_owned(joints.tets[2 * j])) continue;  // a joint lives with its tet A
    const FractureSpec& f = model.joint_laws[static_cast<std::size_t>(joints.law[j])].fracture;
    std::uint64_t h = 0xcbf29ce484222325ULL;
    const GlobalId index = joints.gid[j] - model.gid_offset;
    fnv_mix(h, &index, sizeof(GlobalId));
    fnv_mix(h, &f.tensile_strength, sizeof(double));
    fnv_mix(h, &f.cohesion, sizeof(double));
    sum += finish(h);
  }
  return sum;
}

std::string hash_to_hex(std::uint64_t hash) {
  static const char* digits = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) s[i] = digits[hash & 0xf];
  return s;
}

}  // namespace fdem
