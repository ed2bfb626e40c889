// Random tetrahedron clouds for the contact-detection tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "contact/broad_phase.hpp"
#include "contact/nbs.hpp"

namespace fdem::test {

// n tetrahedra (4 nodes each, nodes not shared): centres uniform in the box
// [origin, origin + size], characteristic edge length log-uniform in [h_min, h_max] (m).
struct TetCloud {
  LocalIndex n = 0;
  std::vector<double> x;  // 12 doubles per tet: 4 nodes, xyz
  std::vector<double> lo, hi;

  void update_boxes() {
    lo.assign(3 * n, 0.0);
    hi.assign(3 * n, 0.0);
    for (LocalIndex e = 0; e < n; ++e) {
      for (int k = 0; k < 3; ++k) {
        double mn = x[12 * e + k], mx = mn;
        for (int v = 1; v < 4; ++v) {
          mn = std::min(mn, x[12 * e + 3 * v + k]);
          mx = std::max(mx, x[12 * e + 3 * v + k]);
        }
        lo[3 * e + k] = mn;
        hi[3 * e + k] = mx;
      }
    }
  }
};

inline TetCloud random_tets(LocalIndex n, std::array<double, 3> origin, std::array<double, 3> size,
                            double h_min, double h_max, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  TetCloud cloud;
  cloud.n = n;
  cloud.x.resize(12 * static_cast<std::size_t>(n));
  for (LocalIndex e = 0; e < n; ++e) {
    const double h = h_min * std::pow(h_max / h_min, unit(rng));
    double centre[3];
    for (int k = 0; k < 3; ++k) centre[k] = origin[k] + size[k] * unit(rng);
    for (int v = 0; v < 4; ++v) {
      for (int k = 0; k < 3; ++k) cloud.x[12 * e + 3 * v + k] = centre[k] + h * (unit(rng) - 0.5);
    }
  }
  cloud.update_boxes();
  return cloud;
}

// Cube side that holds n tets of size h at the given volume fraction of their boxes.
inline double side_for(LocalIndex n, double h, double fraction) {
  return std::cbrt(static_cast<double>(std::max<LocalIndex>(n, 1)) * h * h * h / fraction);
}

}  // namespace fdem::test
