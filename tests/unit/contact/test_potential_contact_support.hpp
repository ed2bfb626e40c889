// Random tets and pair configurations for the potential-contact and friction tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "contact/potential_contact_kernels.hpp"

namespace fdem::test_contact {

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

inline double signed_volume(const TetCorners& t) {
  return (t.x[1] - t.x[0]).dot((t.x[2] - t.x[0]).cross(t.x[3] - t.x[0])) / 6.0;
}

// A regular tet of edge `size`, randomly deformed (each corner moved by up to `distortion`*size),
// rotated and placed at `center`.  Rejects slivers (volume < 30 % of the regular one).  Random
// orientation (either sign of the volume) when `any_orientation`.
inline TetCorners random_tet(std::mt19937_64& rng, double size, const Vec3& center,
                             double distortion = 0.25, bool any_orientation = true) {
  const Vec3 regular[4] = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double scale = size / std::sqrt(8.0);
  const double regular_volume = size * size * size / (6.0 * std::sqrt(2.0));
  for (;;) {
    const Mat3 rot = random_rotation(rng);
    TetCorners t;
    for (int v = 0; v < 4; ++v) {
      const Vec3 p = regular[v] * scale + distortion * size * Vec3(u(rng), u(rng), u(rng));
      t.x[v] = center + rot * p;
    }
    if (std::abs(signed_volume(t)) < 0.3 * regular_volume) continue;
    if (!any_orientation && signed_volume(t) < 0) std::swap(t.x[1], t.x[2]);
    if (any_orientation && u(rng) < 0) std::swap(t.x[1], t.x[2]);
    return t;
  }
}

inline Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

// A pair whose exact overlap is non-empty: target of size ~1 at `origin`, contactor of a random
// size in [0.3, 2] at a random offset.
inline void random_overlapping_pair(std::mt19937_64& rng, const Vec3& origin, TetCorners& c,
                                    TetCorners& t, double penalty = 1.0) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (;;) {
    t = random_tet(rng, 1.0, origin);
    const double size = 0.3 + 1.7 * u(rng);
    c = random_tet(rng, size, origin + 0.6 * u(rng) * random_unit(rng));
    if (potential_contact_unculled(c, t, penalty).overlapping) return;
  }
}

// The upper tet's bottom face in the lower tet's top face plane (z = 0), pressed `depth` into
// it, shifted and turned in the plane: blocks resting on blocks with unmatched meshes.
inline void face_on_face(std::mt19937_64& rng, double depth, TetCorners& lower, TetCorners& upper) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Mat3 spin = Eigen::AngleAxisd(2.0 * M_PI * u(rng), Vec3::UnitZ()).toRotationMatrix();
  const Vec3 shift(1.2 * u(rng) - 0.6, 1.2 * u(rng) - 0.6, -depth);
  lower.x[0] = Vec3(0, 0, 0);
  lower.x[1] = Vec3(1, 0, 0);
  lower.x[2] = Vec3(0, 1, 0);
  lower.x[3] = Vec3(0.3 + 0.4 * u(rng), 0.3 + 0.4 * u(rng), -0.5 - 0.5 * u(rng));
  for (int v = 0; v < 3; ++v) upper.x[v] = spin * lower.x[v] + shift;
  upper.x[3] = spin * Vec3(0.3 + 0.4 * u(rng), 0.3 + 0.4 * u(rng), 0.5 + 0.5 * u(rng)) + shift;
}

}  // namespace fdem::test_contact
