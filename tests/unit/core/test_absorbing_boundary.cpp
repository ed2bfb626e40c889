// The Lysmer–Kuhlemeyer face kernel: normal and tangential parts of the velocity meet their own
// impedance, each node carries a third of the face.
#include <catch2/catch.hpp>

#include "core/absorbing_boundary.hpp"

using namespace fdem;

TEST_CASE("lk_face_forces: ρc_p on the normal, ρc_s on the tangential velocity, A/3 per node",
          "[absorbing]") {
  const Vec3 n = Vec3(1, 2, 2) / 3.0;                   // unit
  const double area = 0.6, z_p = 5e6, z_s = 3e6;        // m², Pa·s/m
  const double v0[3] = {2 * n[0], 2 * n[1], 2 * n[2]};  // normal, 2 m/s
  const Vec3 t = Vec3(2, -1, 0) / std::sqrt(5.0);       // tangent (t·n = 0)
  const double v1[3] = {0.5 * t[0], 0.5 * t[1], 0.5 * t[2]};
  const double v2[3] = {2 * n[0] + 0.5 * t[0], 2 * n[1] + 0.5 * t[1], 2 * n[2] + 0.5 * t[2]};
  const double* v[3] = {v0, v1, v2};
  double f[9];
  lk_face_forces(v, n, area, z_p, z_s, f);
  for (int k = 0; k < 3; ++k) {
    CHECK(f[k] == Approx(-0.2 * z_p * 2 * n[k]));  // 0.2 = A/3
    CHECK(f[3 + k] == Approx(-0.2 * z_s * 0.5 * t[k]).margin(1e-9));
    CHECK(f[6 + k] == Approx(-0.2 * (z_p * 2 * n[k] + z_s * 0.5 * t[k])));  // superposed
  }
}
