// Four doubles side by side: the vector type of the kernels that compute four elements (tets,
// joints) at once, one per lane.  GCC/Clang vector extensions: one instruction for the four lanes
// on AVX2, two on the x86-64 baseline (SSE2); every lane rounds exactly as the scalar operation
// would (builds use -ffp-contract=off, so no a·b + c is fused), which is what lets a kernel written
// once for `double` and for `Lanes` give the same bits on both.
#pragma once

#include <cmath>
#include <cstring>

namespace fdem {

using Lanes = double __attribute__((vector_size(32)));
using LaneMask = long long __attribute__((vector_size(32)));
constexpr int lane_count = 4;

// The same operation on one value or on four, for kernels templated on their scalar type.
inline double select(bool take_first, double a, double b) {
  return take_first ? a : b;
}
// `take_first`: a lane comparison's result (a vector of 64-bit integers, −1 where true).
template <class Mask>
inline Lanes select(Mask take_first, Lanes a, Lanes b) {
  return take_first ? a : b;
}
// Lane i holds i: `lane_index() == k` is the mask of lane k alone.  (A lane chosen by such a mask
// stays in registers; writing one lane at a variable index sends the vector through memory, and
// the load after the store stalls.)
inline LaneMask lane_index() {
  return LaneMask{0, 1, 2, 3};
}
// One value in every lane.
inline Lanes splat(double x) {
  return Lanes{x, x, x, x};
}
// Four doubles from memory and back (any alignment).
inline Lanes load_lanes(const double* from) {
  Lanes out;
  std::memcpy(&out, from, sizeof out);
  return out;
}
inline void store_lanes(const Lanes& value, double* to) {
  std::memcpy(to, &value, sizeof value);
}
inline double log_of(double x) {
  return std::log(x);
}
inline Lanes log_of(Lanes x) {  // libm's logarithm lane by lane: the scalar path's bits
  return Lanes{std::log(x[0]), std::log(x[1]), std::log(x[2]), std::log(x[3])};
}
}  // namespace fdem
