// 3 × 3 matrix arithmetic on nine values, column-major (m[i + 3j] is row i, column j, as
// TetArrays::dm_inv and Eigen's Mat3 store them), for one element (T = double) or four side by side
// (T = Lanes, core/lanes.hpp).  Every sum has a fixed order, written out here, so the one-element
// and four-lane instances give the same bits on every build (Eigen's own products and reductions
// change their order with the vector width they are compiled for).
#pragma once

#include "core/lanes.hpp"

namespace fdem::small_matrix {

// The three products of row i of a product, t0 + t1 + t2, summed as Eigen's SSE2 build sums them
// (rows 0 and 1 in a vector register, row 2 alone): the results are the bits of the Eigen kernels
// these functions replaced.
template <class T>
inline T row_sum(int i, T t0, T t1, T t2) {
  return i < 2 ? (t0 + t1) + t2 : t0 + (t1 + t2);
}

// c = a·b: c(i,j) = Σ_k a(i,k)·b(k,j).
template <class T>
inline void product(const T (&a)[9], const T (&b)[9], T (&c)[9]) {
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      c[i + 3 * j] = row_sum(i, a[i] * b[3 * j], a[i + 3] * b[1 + 3 * j], a[i + 6] * b[2 + 3 * j]);
}

// c = a·bᵀ: c(i,j) = Σ_k a(i,k)·b(j,k).
template <class T>
inline void product_transposed(const T (&a)[9], const T (&b)[9], T (&c)[9]) {
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      c[i + 3 * j] = row_sum(i, a[i] * b[j], a[i + 3] * b[j + 3], a[i + 6] * b[j + 6]);
}

// c = aᵀ·b: c(i,j) = Σ_k a(k,i)·b(k,j), k in order.
template <class T>
inline void transposed_product(const T (&a)[9], const T (&b)[9], T (&c)[9]) {
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      c[i + 3 * j] =
          (a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1]) + a[3 * i + 2] * b[3 * j + 2];
}

// det m by the first row's cofactors: (m00·c00 − m01·c01') + m02·c02'.
template <class T>
inline T determinant(const T (&m)[9]) {
  const auto at = [&m](int i, int j) { return m[i + 3 * j]; };
  const auto minor = [&at](int a, int b, int c) {
    return at(0, a) * (at(1, b) * at(2, c) - at(1, c) * at(2, b));
  };
  return (minor(0, 1, 2) - minor(1, 0, 2)) + minor(2, 0, 1);
}

// m⁻ᵀ from the cofactors: m⁻ᵀ(i,j) = cof(i,j)/det, with det = Σ_i cof(i,0)·m(i,0) (the
// cofactors' own determinant, in order).
template <class T>
inline void inverse_transposed(const T (&m)[9], T (&out)[9]) {
  const auto at = [&m](int i, int j) { return m[i + 3 * j]; };
  const auto cofactor = [&at](int i, int j) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    return at(i1, j1) * at(i2, j2) - at(i1, j2) * at(i2, j1);
  };
  const T c00 = cofactor(0, 0), c10 = cofactor(1, 0), c20 = cofactor(2, 0);
  const T inverse_det = 1.0 / ((c00 * at(0, 0) + c10 * at(1, 0)) + c20 * at(2, 0));
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) out[i + 3 * j] = cofactor(i, j) * inverse_det;
}

// Σ a(e)·b(e) over the nine entries, pairwise: even and odd entries of the first eight in two
// interleaved trees, then the ninth.
template <class T>
inline T contraction(const T (&a)[9], const T (&b)[9]) {
  T p[9];
  for (int e = 0; e < 9; ++e) p[e] = a[e] * b[e];
  return (((p[0] + p[2]) + (p[4] + p[6])) + ((p[1] + p[3]) + (p[5] + p[7]))) + p[8];
}

}  // namespace fdem::small_matrix
