// The critical step of one tetrahedron: 2/ω_max of its lumped-mass stiffness, found from a
// stiffness matrix assembled by differencing the internal forces; central difference is stable
// just below it and grows just above it.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/dynamics.hpp"
#include "core/model_builder.hpp"
#include "core/tet_kernels.hpp"
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
      largest = std::max(largest, std::abs(model.nodes.x[i] - model.nodes.x0(i / 3)[i % 3]));
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

namespace {

// A cube of n³ cells of `size` (m), 6 Kuhn tets each, nodes moved at random by up to `jitter`
// cells; `split` gives every tet its own four nodes, as in a body with joints on every face.
Model kuhn_cube(int n, double size, double jitter, bool split, double poisson, double damping,
                unsigned seed) {
  Scene scene = test::one_rock_body("cube", damping);
  scene.materials[0].elastic.poisson = poisson;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int m = n + 1;
  std::vector<double> grid;
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i)
        for (const int c : {i, j, k}) grid.push_back(size * (c + jitter * unit(rng)));
  const auto corner = [&](int i, int j, int k, int bit) {
    return (i + (bit & 1)) + m * ((j + ((bit >> 1) & 1)) + m * (k + ((bit >> 2) & 1)));
  };
  const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  BodyMesh mesh;
  mesh.source = "test";
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& path : paths) {
          int tet[4] = {corner(i, j, k, 0), corner(i, j, k, path[0]), corner(i, j, k, path[1]),
                        corner(i, j, k, 7)};
          Vec3 x[4];
          for (int c = 0; c < 4; ++c)
            x[c] = Vec3(grid[3 * tet[c]], grid[3 * tet[c] + 1], grid[3 * tet[c] + 2]);
          if (tet_reference(x).volume < 0.0) std::swap(tet[2], tet[3]);
          for (const int node : tet) {
            if (!split) {
              mesh.tets.push_back(node);
              continue;
            }
            mesh.tets.push_back(static_cast<int>(mesh.coords.size() / 3));
            for (int c = 0; c < 3; ++c) mesh.coords.push_back(grid[3 * node + c]);
          }
        }
  if (!split) mesh.coords = grid;
  return build_model(scene, {mesh});
}

}  // namespace

TEST_CASE("the cheap lower bound of the critical step is below the exact one and within 3× of it",
          "[time_step]") {
  double lowest = 1.0, highest = 0.0;
  unsigned seed = 1;
  for (const double poisson : {-0.3, 0.0, 0.25, 0.45})
    for (const double damping : {0.0, 0.1})
      for (const bool split : {false, true})
        for (const double jitter : {0.0, 0.25}) {
          Model model = kuhn_cube(3, 0.1, jitter, split, poisson, damping, ++seed);
          const double exact = critical_time_step(model).dt;
          const double bound = critical_time_step_lower_bound(model);
          INFO("ν " << poisson << ", damping " << damping << ", split " << split << ", jitter "
                    << jitter << ": bound " << bound << " s, exact " << exact << " s");
          REQUIRE(bound <= exact);
          REQUIRE(bound >= exact / 3.0);
          // Each tet on its own: the bound holds tet by tet too (the minimum above could hide one).
          Model moved = model;
          for (double& x : moved.nodes.x) x *= 1.0 + 1e-3 * std::sin(x * 1e3);  // a deformed state
          REQUIRE(critical_time_step_lower_bound(moved) <= critical_time_step(moved).dt);
          lowest = std::min(lowest, bound / exact);
          highest = std::max(highest, bound / exact);
        }
  std::printf("  lower bound / exact critical step: %.3f to %.3f\n", lowest, highest);
}
