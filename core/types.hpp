// Basic value types shared by every folder: 3-vectors, 3x3 matrices, ids.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <utility>

namespace fdem {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Global ids never change (across ranks, restarts, migration); local indices address the
// [owned | ghost] arrays of one rank.
using GlobalId = std::int64_t;
using LocalIndex = std::int32_t;

// Most nodes, tets or joints one rank may hold.  Local indices are 32-bit, and the arrays are
// addressed as k·index + c with k up to 9 (Dm⁻¹: 9 doubles per tet), so 9·index must fit an
// int32 too: 238,609,294 (a whole model is bounded only by its 64-bit gids: use more ranks).
constexpr std::int64_t max_local_entries = 0x7fffffff / 9;

// View of node i's xyz triple inside a flat array of 3*n doubles.
inline Eigen::Map<Vec3> vec3_at(double* xyz, LocalIndex i) {
  return Eigen::Map<Vec3>(xyz + 3 * i);
}
inline Eigen::Map<const Vec3> vec3_at(const double* xyz, LocalIndex i) {
  return Eigen::Map<const Vec3>(xyz + 3 * i);
}

// Empties a container (or a struct of them) and gives its memory back.  (`values = {}` does not:
// for a std::vector it assigns an empty initializer list, which keeps the capacity.)
template <class Container>
void release(Container& container) {
  Container empty{};
  using std::swap;
  swap(container, empty);
}

// ⌊a·b/c⌋ for 0 ≤ a, b and c > 0 without overflow of the product (block and directory ranks of
// 64-bit ids: a·b may exceed 2^63).
inline std::int64_t mul_div(std::int64_t a, std::int64_t b, std::int64_t c) {
  __extension__ typedef __int128 wide;
  return static_cast<std::int64_t>(static_cast<wide>(a) * b / c);
}

}  // namespace fdem
