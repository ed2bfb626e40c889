// Pure per-tetrahedron kernels: reference shape, deformation gradient, internal force, stability.
// Constant-strain 4-node tetrahedron, total Lagrangian: F = Ds·Dm⁻¹ with Ds = [x1−x0, x2−x0,
// x3−x0].
#pragma once

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/materials.hpp"
#include "core/tet_force_kernel.hpp"
#include "core/types.hpp"

namespace fdem {

struct TetReference {
  Mat3 dm_inv;    // inverse of the reference edge matrix Dm (1/m)
  double volume;  // signed reference volume (m^3); ≤ 0 means inverted or degenerate
};

inline Mat3 edge_matrix(const Vec3 (&x)[4]) {
  Mat3 d;
  d.col(0) = x[1] - x[0];
  d.col(1) = x[2] - x[0];
  d.col(2) = x[3] - x[0];
  return d;
}

inline TetReference tet_reference(const Vec3 (&X)[4]) {
  const Mat3 dm = edge_matrix(X);
  const double det = dm.determinant();
  TetReference ref;
  ref.volume = det / 6.0;
  ref.dm_inv = det != 0.0 ? Mat3(dm.inverse()) : Mat3::Zero();
  return ref;
}

// Gradients of the four linear shape functions in the reference configuration (1/m), as columns.
inline Eigen::Matrix<double, 3, 4> shape_gradients(const Mat3& dm_inv) {
  Eigen::Matrix<double, 3, 4> g;
  g.rightCols<3>() = dm_inv.transpose();
  g.col(0) = -g.col(1) - g.col(2) - g.col(3);
  return g;
}

// Smallest altitude 3V/A_max of a tetrahedron (m): its characteristic size for stability and
// penalties.
inline double smallest_altitude(const Vec3 (&x)[4]) {
  const double volume = std::abs(edge_matrix(x).determinant()) / 6.0;
  double max_area = 0.0;
  for (int skip = 0; skip < 4; ++skip) {
    const Vec3& a = x[(skip + 1) % 4];
    const Vec3& b = x[(skip + 2) % 4];
    const Vec3& c = x[(skip + 3) % 4];
    max_area = std::max(max_area, 0.5 * (b - a).cross(c - a).norm());
  }
  return max_area > 0.0 ? 3.0 * volume / max_area : 0.0;
}

struct TetForce {
  Vec3 force[4];         // internal (elastic + viscous) force on each corner (N)
  double strain_energy;  // W(F)·V0 (J)
  double damping_power;  // viscous dissipation rate V0·P_v:Ḟ (W), ≥ 0
  double jacobian;       // det F; ≤ 0 means the element inverted (forces not computed)
};

// Internal force of one tetrahedron (core/tet_force_kernel.hpp with Eigen types).  x, v: current
// corner positions (m) and velocities (m/s); viscosity η (Pa·s) adds the viscous Cauchy stress
// 2η·sym(ḞF⁻¹).
template <class Material>
inline TetForce tet_internal_force(const Vec3 (&x)[4], const Vec3 (&v)[4], const Mat3& dm_inv,
                                   double volume0, const Material& material, double viscosity) {
  double xs[4][3], vs[4][3], d[9];
  for (int c = 0; c < 4; ++c)
    for (int i = 0; i < 3; ++i) {
      xs[c][i] = x[c][i];
      vs[c][i] = v[c][i];
    }
  for (int e = 0; e < 9; ++e) d[e] = dm_inv.data()[e];
  TetCornerForces<double> f;
  const typename Material::template Law<double> law{material.lame.lambda, material.lame.mu};
  tet_corner_forces(xs, vs, d, volume0, law, viscosity, viscosity > 0.0, f);
  TetForce out;
  for (int c = 0; c < 4; ++c) out.force[c] = Vec3(f.force[c][0], f.force[c][1], f.force[c][2]);
  out.strain_energy = f.strain_energy;
  out.damping_power = f.damping_power;
  out.jacobian = f.jacobian;
  return out;
}

// Largest eigenvalue of M⁻¹K for one tet: K = V·BᵀCB (isotropic small-strain stiffness), M the
// diagonal matrix of the masses given to its corners (kg; 1 each → eigenvalue of K in N/m).  Uses
// the 6×6 matrix V·LᵀB'B'ᵀL (C = LLᵀ, B' = B·M^-1/2) that has the same non-zero spectrum.
inline double tet_max_eigenvalue(const Mat3& dm_inv, double volume, LameParameters lame,
                                 const double (&corner_mass)[4]) {
  const Eigen::Matrix<double, 3, 4> g = shape_gradients(dm_inv);
  Eigen::Matrix<double, 6, 12> B =
      Eigen::Matrix<double, 6, 12>::Zero();  // Voigt, engineering shear
  for (int a = 0; a < 4; ++a) {
    const double s = 1.0 / std::sqrt(corner_mass[a]);
    const double gx = s * g(0, a), gy = s * g(1, a), gz = s * g(2, a);
    B(0, 3 * a + 0) = gx;
    B(1, 3 * a + 1) = gy;
    B(2, 3 * a + 2) = gz;
    B(3, 3 * a + 1) = gz;
    B(3, 3 * a + 2) = gy;
    B(4, 3 * a + 0) = gz;
    B(4, 3 * a + 2) = gx;
    B(5, 3 * a + 0) = gy;
    B(5, 3 * a + 1) = gx;
  }
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>().setConstant(lame.lambda);
  C.topLeftCorner<3, 3>().diagonal().setConstant(lame.lambda + 2.0 * lame.mu);
  C.bottomRightCorner<3, 3>().diagonal().setConstant(lame.mu);
  const Eigen::Matrix<double, 6, 6> L = Eigen::LLT<Eigen::Matrix<double, 6, 6>>(C).matrixL();
  const Eigen::Matrix<double, 6, 6> A = std::abs(volume) * L.transpose() * B * B.transpose() * L;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(A, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().maxCoeff();
}

inline double tet_max_stiffness_eigenvalue(const Mat3& dm_inv, double volume, LameParameters lame) {
  const double unit[4] = {1.0, 1.0, 1.0, 1.0};
  return tet_max_eigenvalue(dm_inv, volume, lame, unit);
}

// Critical central-difference step (s) for a highest angular frequency ω (rad/s) with damping
// ratio ξ of that mode: Δt = (2/ω)(√(1+ξ²) − ξ).
inline double critical_step_for_frequency(double omega, double damping_ratio) {
  return 2.0 / omega * (std::sqrt(1.0 + damping_ratio * damping_ratio) - damping_ratio);
}

// Critical step of one tet alone with lumped mass ρV/4 per node.
inline double tet_critical_time_step(double max_stiffness_eigenvalue, double density, double volume,
                                     double damping_ratio) {
  return critical_step_for_frequency(
      std::sqrt(max_stiffness_eigenvalue / (density * std::abs(volume) / 4.0)), damping_ratio);
}

}  // namespace fdem
