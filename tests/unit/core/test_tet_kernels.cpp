// Tet kinematics and materials: objectivity, patch test, agreement at small strain, consistency.
#include <catch2/catch.hpp>
#include <random>

#include "core/tet_kernels.hpp"

using namespace fdem;

namespace {

const Vec3 reference_tet[4] = {Vec3(0.1, -0.2, 0.05), Vec3(1.3, 0.1, -0.1), Vec3(0.2, 0.9, 0.3),
                               Vec3(-0.1, 0.3, 1.1)};
const LameParameters lame = LameParameters::from_young_poisson(30e9, 0.25);

Mat3 rotation(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

template <class Material>
TetForce force_for(const Mat3& F, const Vec3& shift, const Material& material,
                   double viscosity = 0.0, const Mat3& velocity_gradient = Mat3::Zero()) {
  Vec3 X[4];
  std::copy(std::begin(reference_tet), std::end(reference_tet), X);
  const TetReference ref = tet_reference(X);
  Vec3 x[4], v[4];
  for (int c = 0; c < 4; ++c) {
    x[c] = F * X[c] + shift;
    v[c] = velocity_gradient * X[c];
  }
  return tet_internal_force(x, v, ref.dm_inv, ref.volume, material, viscosity);
}

double max_force(const TetForce& f) {
  double m = 0;
  for (const auto& v : f.force) m = std::max(m, v.norm());
  return m;
}

}  // namespace

TEST_CASE("rigid rotations up to 180 degrees give zero strain, stress and force", "[tet]") {
  // Scale: the force a 1 % stretch would produce.
  const double scale =
      max_force(force_for(Mat3(Vec3(1.01, 1, 1).asDiagonal()), Vec3::Zero(), NeoHookean{lame}));
  for (double angle : {1e-3, 0.5, 1.0, 2.0, 3.0, M_PI}) {
    for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(1, 1, 1), Vec3(-0.3, 0.7, 0.2)}) {
      const Mat3 Q = rotation(axis, angle);
      const TetForce nh = force_for(Q, Vec3(3, -2, 7), NeoHookean{lame});
      const TetForce svk = force_for(Q, Vec3(3, -2, 7), StVenantKirchhoff{lame});
      CHECK(max_force(nh) <= 1e-12 * scale);
      CHECK(max_force(svk) <= 1e-12 * scale);
      CHECK(std::abs(nh.strain_energy) <= 1e-12 * 1e9);
      CHECK(std::abs(svk.strain_energy) <= 1e-12 * 1e9);
      CHECK(nh.jacobian == Approx(1.0).epsilon(1e-14));
      CHECK(StVenantKirchhoff{lame}.first_piola(Q).norm() <= 1e-12 * lame.mu);
      CHECK(NeoHookean{lame}.first_piola(Q).norm() <= 1e-12 * lame.mu);
    }
  }
}

TEST_CASE("homogeneous stretch gives the exact stress (St. Venant-Kirchhoff and neo-Hookean)",
          "[tet]") {
  const double e = 0.02;
  const Mat3 F = Vec3(1 + e, 1, 1).asDiagonal();
  // SVK: E11 = ((1+e)^2 - 1)/2, S = λ trE I + 2μE, P = F S.
  const double E11 = 0.5 * ((1 + e) * (1 + e) - 1);
  Mat3 S = lame.lambda * E11 * Mat3::Identity();
  S(0, 0) += 2 * lame.mu * E11;
  const Mat3 P_svk = F * S;
  CHECK((StVenantKirchhoff{lame}.first_piola(F) - P_svk).norm() <= 1e-12 * P_svk.norm());
  // Neo-Hookean: P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ with J = 1+e.
  const Mat3 Fit = F.inverse().transpose();
  const Mat3 P_nh = lame.mu * (F - Fit) + lame.lambda * std::log(1 + e) * Fit;
  CHECK((NeoHookean{lame}.first_piola(F) - P_nh).norm() <= 1e-12 * P_nh.norm());
  // The element's nodal forces are −V·P·∇N: their sum is zero and they equal the traction on faces.
  const TetForce f = force_for(F, Vec3::Zero(), StVenantKirchhoff{lame});
  Vec3 total = Vec3::Zero();
  for (const auto& v : f.force) total += v;
  CHECK(total.norm() <= 1e-12 * max_force(f));
  // Face opposite corner 0 has outward area vector A n; its corners carry −P·(A n)/3 each... summed
  // over the element, Σ_a f_a ⊗ X_a = −V·P (the virial identity for a homogeneous state).
  Vec3 X[4];
  std::copy(std::begin(reference_tet), std::end(reference_tet), X);
  Mat3 virial = Mat3::Zero();
  for (int a = 0; a < 4; ++a) virial += f.force[a] * X[a].transpose();
  const double volume = tet_reference(X).volume;
  CHECK((virial + volume * P_svk).norm() <= 1e-11 * volume * P_svk.norm());
}

TEST_CASE("both materials agree at small strain", "[tet]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    Mat3 H;
    for (int i = 0; i < 9; ++i) H(i) = u(rng);
    for (double eps : {1e-3, 1e-4, 1e-5}) {
      const Mat3 F = Mat3::Identity() + eps * H;
      const Mat3 a = StVenantKirchhoff{lame}.first_piola(F), b = NeoHookean{lame}.first_piola(F);
      // The difference is second order in the strain.
      CHECK((a - b).norm() <= 20.0 * eps * a.norm());
    }
  }
}

TEST_CASE("nodal forces are minus the gradient of the strain energy", "[tet]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  Vec3 X[4];
  std::copy(std::begin(reference_tet), std::end(reference_tet), X);
  const TetReference ref = tet_reference(X);
  Vec3 x[4], v[4];
  for (int c = 0; c < 4; ++c) {
    x[c] = X[c] + Vec3(u(rng), u(rng), u(rng));
    v[c].setZero();
  }
  for (int model = 0; model < 2; ++model) {
    auto energy = [&](const Vec3(&y)[4]) {
      return model == 0
                 ? tet_internal_force(y, v, ref.dm_inv, ref.volume, NeoHookean{lame}, 0)
                       .strain_energy
                 : tet_internal_force(y, v, ref.dm_inv, ref.volume, StVenantKirchhoff{lame}, 0)
                       .strain_energy;
    };
    const TetForce f =
        model == 0 ? tet_internal_force(x, v, ref.dm_inv, ref.volume, NeoHookean{lame}, 0)
                   : tet_internal_force(x, v, ref.dm_inv, ref.volume, StVenantKirchhoff{lame}, 0);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) {
        const double h = 1e-7;
        Vec3 xp[4], xm[4];
        std::copy(x, x + 4, xp);
        std::copy(x, x + 4, xm);
        xp[c][k] += h;
        xm[c][k] -= h;
        const double numeric = -(energy(xp) - energy(xm)) / (2 * h);
        CHECK(f.force[c][k] == Approx(numeric).epsilon(1e-5).margin(1e-6 * max_force(f)));
      }
  }
}

TEST_CASE("objectivity: a pre-stretched tet turned through a full turn keeps S, rotates sigma",
          "[tet]") {
  // docs/references.md 4(a): x = Q(t)·1.01·X about (1,1,1)/√3.
  const Mat3 U = 1.01 * Mat3::Identity();
  const Mat3 P0 = NeoHookean{lame}.first_piola(U);
  const Mat3 S0 = U.inverse() * P0;
  const Mat3 sigma0 = P0 * U.transpose() / U.determinant();
  for (int i = 0; i <= 36; ++i) {
    const Mat3 Q = rotation(Vec3(1, 1, 1), 2 * M_PI * i / 36);
    const Mat3 F = Q * U;
    for (int model = 0; model < 2; ++model) {
      const Mat3 P =
          model == 0 ? NeoHookean{lame}.first_piola(F) : StVenantKirchhoff{lame}.first_piola(F);
      const Mat3 P_ref = model == 0 ? P0 : StVenantKirchhoff{lame}.first_piola(U);
      const Mat3 S = F.inverse() * P, S_ref = U.inverse() * P_ref;
      const Mat3 sigma = P * F.transpose() / F.determinant();
      const Mat3 sigma_ref = Q * (P_ref * U.transpose() / U.determinant()) * Q.transpose();
      CHECK((S - S_ref).norm() <= 1e-12 * S_ref.norm());
      CHECK((sigma - sigma_ref).norm() <= 1e-12 * sigma_ref.norm());
    }
  }
  (void)S0;
  (void)sigma0;
}

TEST_CASE("viscous damping dissipates and vanishes under rigid spin", "[tet]") {
  const Mat3 W = (Mat3() << 0, -2, 1, 2, 0, -3, -1, 3, 0).finished();  // skew: rigid spin rate
  const double scale =
      max_force(force_for(Mat3(Vec3(1.01, 1, 1).asDiagonal()), Vec3::Zero(), NeoHookean{lame}));
  const TetForce spin = force_for(Mat3::Identity(), Vec3::Zero(), NeoHookean{lame}, 1e5, W);
  CHECK(max_force(spin) <= 1e-12 * scale);
  CHECK(std::abs(spin.damping_power) <= 1e-12);
  const Mat3 D = (Mat3() << 1, 0.2, 0, 0.2, -0.5, 0.1, 0, 0.1, 0.3).finished();
  const TetForce stretching = force_for(Mat3::Identity(), Vec3::Zero(), NeoHookean{lame}, 1e5, D);
  CHECK(stretching.damping_power > 0.0);
  // Power = 2η D:D V for F = I.
  Vec3 X[4];
  std::copy(std::begin(reference_tet), std::end(reference_tet), X);
  CHECK(stretching.damping_power ==
        Approx(2e5 * D.squaredNorm() * tet_reference(X).volume).epsilon(1e-12));
}

TEST_CASE("stiffness eigenvalue bound matches a 1D estimate for a regular tet", "[tet]") {
  // Regular tet, ν = 0: the critical step must lie between h/(2c) and h/c (h = altitude).
  const Vec3 X[4] = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  Vec3 Y[4] = {X[0], X[1], X[3], X[2]};
  TetReference ref = tet_reference(Y);
  REQUIRE(ref.volume > 0);
  const LameParameters l0 = LameParameters::from_young_poisson(1e9, 0.0);
  const double k = tet_max_stiffness_eigenvalue(ref.dm_inv, ref.volume, l0);
  const double dt = tet_critical_time_step(k, 1000.0, ref.volume, 0.0);
  const double h = smallest_altitude(Y), c = std::sqrt(1e9 / 1000.0);
  CHECK(dt > 0.5 * h / c);
  CHECK(dt < h / c);
  // Damping shortens the step by (√(1+ξ²) − ξ).
  CHECK(tet_critical_time_step(k, 1000.0, ref.volume, 0.1) == Approx(dt * (std::sqrt(1.01) - 0.1)));
}
