// The critical step of one tetrahedron: 2/ω_max of its lumped-mass stiffness, found from a
// stiffness matrix assembled by differencing the internal forces; central difference is stable
// just below it and grows just above it.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>

#include "core/dynamics.hpp"
#include "core/model_builder.hpp"
#include "core/time_step.hpp"
#include "one_body_scene.hpp"

using namespace fdem;

namespace {

// One irregular tet of rock, free in space.
Model one_tet() {
  const Scene scene = test::one_rock_body("tet");
  BodyMesh mesh;
  mesh.source = "test";
  mesh.coords = {0.0, 0.0, 0.0, 0.11, 0.01, 0.0, 0.02, 0.09, 0.01, 0.03, 0.02, 0.13};
  mesh.tets = {0, 1, 2, 3};
  return build_model(scene, {mesh});
}

// The 12×12 stiffness at the reference shape, by central differences of the internal forces.
Eigen::MatrixXd stiffness(Model& model) {
  Eigen::MatrixXd k(12, 12);
  const double h = 1e-9;  // m: the forces are linear to ~h/size = 1e-8 at this step
  for (int j = 0; j < 12; ++j) {
    const double x = model.nodes.x[j];
    model.nodes.x[j] = x + h;
    compute_internal_forces(model);
    const std::vector<double> plus = model.nodes.f;
    model.nodes.x[j] = x - h;
    compute_internal_forces(model);
    for (int i = 0; i < 12; ++i) k(i, j) = -(plus[i] - model.nodes.f[i]) / (2.0 * h);
    model.nodes.x[j] = x;
  }
  return 0.5 * (k + k.transpose());
}

// Largest displacement from the reference over `steps` steps of central difference after a
// velocity `v0` along the stiffest mode.
double run(Model model, double dt, const Eigen::VectorXd& v0, int steps, int from) {
  for (int i = 0; i < 12; ++i) model.nodes.v[i] = v0[i];
  double largest = 0.0;
  for (int s = 0; s < steps; ++s) {
    compute_internal_forces(model);
    integrate_central_difference(dt, model.nodes);
    if (s < from) continue;
    for (int i = 0; i < 12; ++i)
      largest = std::max(largest, std::abs(model.nodes.x[i] - model.nodes.x0[i]));
  }
  return largest;
}

}  // namespace

TEST_CASE("critical step of one tet: 2/ω_max of its lumped-mass stiffness, the stability limit",
          "[time_step]") {
  Model model = one_tet();
  REQUIRE(model.tets.size() == 1);
  const Eigen::MatrixXd k = stiffness(model);
  Eigen::VectorXd inverse_sqrt_mass(12);
  for (int i = 0; i < 12; ++i) inverse_sqrt_mass[i] = 1.0 / std::sqrt(model.nodes.mass[i / 3]);
  const Eigen::MatrixXd scaled =
      inverse_sqrt_mass.asDiagonal() * k * inverse_sqrt_mass.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> modes(scaled);
  const double omega_max = std::sqrt(modes.eigenvalues()[11]);
  const double exact = 2.0 / omega_max;

  const CriticalStep critical = critical_time_step(model);
  CHECK(critical.limiting_tet == 0);
  CHECK(critical.dt == Approx(exact).epsilon(1e-6));

  // The stiffest mode, as velocities (m/s) small enough to stay linear (amplitude ~1e-9 m).
  const Eigen::VectorXd mode = inverse_sqrt_mass.asDiagonal() * modes.eigenvectors().col(11);
  const Eigen::VectorXd v0 = mode * (1e-9 * omega_max / mode.cwiseAbs().maxCoeff());
  const double early = run(model, 0.98 * exact, v0, 50, 0);
  const double stable = run(model, 0.98 * exact, v0, 2000, 1950);
  const double unstable = run(model, 1.02 * exact, v0, 200, 150);
  CHECK(stable < 2.0 * early);    // bounded
  CHECK(unstable > 1e6 * early);  // |λ| ≈ 1.5 per step: grows without bound
}
