// Basic value types shared by every folder: 3-vectors, 3x3 matrices, ids.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

namespace fdem {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Global ids never change (across ranks, restarts, migration); local indices address the
// [owned | ghost] arrays of one rank.
using GlobalId = std::int64_t;
using LocalIndex = std::int32_t;

// View of node i's xyz triple inside a flat array of 3*n doubles.
inline Eigen::Map<Vec3> vec3_at(double* xyz, LocalIndex i) {
  return Eigen::Map<Vec3>(xyz + 3 * i);
}
inline Eigen::Map<const Vec3> vec3_at(const double* xyz, LocalIndex i) {
  return Eigen::Map<const Vec3>(xyz + 3 * i);
}

}  // namespace fdem
