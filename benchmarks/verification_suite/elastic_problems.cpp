// Verification suite: elastic waves, impacts and frequencies (docs/references.md items 1–5).
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/materials.hpp"
#include "core/model_builder.hpp"
#include "core/tet_kernels.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "drivers/simulation.hpp"
#include "fracture/joint_stage.hpp"
#include "suite.hpp"

namespace fdem::verification_suite {

using namespace fdem::builders;

// ------------------------------------------------------------------------------------------------
// 1. Suddenly stopped bar
// ------------------------------------------------------------------------------------------------
std::vector<Measure> stopped_bar(const Setting& s) {
  const double L = 0.02, E = 205e9, rho = 7850, v0 = 0.1;
  const double c0 = std::sqrt(E / rho), plateau = rho * c0 * v0;
  Scene scene = basic_scene(14e-6, s.dt_fraction);
  scene.materials.push_back(elastic_material(rho, E, 0.0, ElasticModel::st_venant_kirchhoff));
  const int nx = cells_for(L, s.h);
  scene.bodies.push_back(box_body("bar", Vec3(0, 0, 0), Vec3(L, 1e-3, 1e-3), nx, 2, 2));
  scene.bodies[0].velocity = Vec3(v0, 0, 0);
  scene.loads.push_back(load_on_region(Vec3(-1e-9, -1, -1), Vec3(1e-9, 1, 1), Vec3::Zero()));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  std::vector<LocalIndex> probe, free_end;
  for (LocalIndex t = 0; t < model.tets.size(); ++t) {
    double cx = 0;
    for (int c = 0; c < 4; ++c) cx += 0.25 * model.nodes.x0(model.tets.nodes[4 * t + c])[0];
    if (std::abs(cx - L / 2) < std::max(L / 160, 0.5 * L / nx)) probe.push_back(t);
  }
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.x0(n)[0] == L) free_end.push_back(n);
  const StVenantKirchhoff law{model.materials[0].lame};
  auto probe_stress = [&]() {
    double sum = 0;
    for (LocalIndex t : probe) {
      Vec3 x[4];
      for (int c = 0; c < 4; ++c) x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
      const Mat3 F = edge_matrix(x) * Eigen::Map<const Mat3>(model.tets.dm_inv.data() + 9 * t);
      sum += (law.first_piola(F) * F.transpose() / F.determinant())(0, 0);
    }
    return sum / probe.size();
  };
  double arrival = -1, plateau_sum = 0, previous_v = v0, worst_balance = 0;
  int samples = 0;
  std::vector<double> reversals;
  const double t_arrival = 0.5 * L / c0, t_reversal = 2 * L / c0;
  while (sim->time() < scene.time.end) {
    sim->step();
    const double t = sim->time(), stress = probe_stress();
    if (arrival < 0 && stress > 0.5 * plateau) arrival = t;
    if (t > t_arrival + 0.3 * L / c0 && t < t_arrival + 0.8 * L / c0) {
      plateau_sum += stress;
      ++samples;
    }
    double v = 0;
    for (LocalIndex n : free_end) v += model.nodes.v[3 * n] / free_end.size();
    if ((v < 0) != (previous_v < 0)) reversals.push_back(t);
    previous_v = v;
    worst_balance = std::max(worst_balance, sim->energy().balance_error());
  }
  const double reversal = reversals.size() >= 2 ? reversals[1] - reversals[0] : 0;
  return {relative("arrival_time", arrival, t_arrival, 0.02),
          relative("stress_plateau", plateau_sum / std::max(samples, 1), plateau, 0.02),
          relative("reversal_period", reversal, t_reversal, 0.02),
          absolute("energy_balance", worst_balance, 0, 1e-3)};
}

// ------------------------------------------------------------------------------------------------
// 2. Two-bar impact
// ------------------------------------------------------------------------------------------------
std::vector<Measure> two_bar_impact(const Setting& s) {
  const double L = 0.5, E = 200e9, rho = 7800, v = 1.0, w = 0.02;
  const double c0 = std::sqrt(E / rho);
  Scene scene = basic_scene(2.6 * L / c0, s.dt_fraction);
  scene.materials.push_back(elastic_material(rho, E, 0.0, ElasticModel::st_venant_kirchhoff));
  set_penalty(scene.materials[0], s.penalty_ratio);
  const int nx = cells_for(L, s.h), ny = 2;
  scene.bodies.push_back(box_body("left", Vec3(-L, 0, 0), Vec3(0, w, w), nx, ny, ny));
  scene.bodies.push_back(box_body("right", Vec3(1e-6, 0, 0), Vec3(L + 1e-6, w, w), nx, ny, ny));
  scene.bodies[0].velocity = Vec3(v, 0, 0);
  scene.bodies[1].velocity = Vec3(-v, 0, 0);
  auto sim = quiet_simulation(scene);
  sim->step();
  const double kinetic0 = sim->energy().current().kinetic;
  double first = -1, last = -1;
  while (sim->time() < scene.time.end) {
    sim->step();
    if (sim->energy().current().contact > 0) {
      if (first < 0) first = sim->time();
      last = sim->time();
    }
  }
  const double duration = last - first;
  return {relative("contact_time", duration, 2 * L / c0, 0.02),
          relative("interface_stress", 2 * rho * L * v / duration, rho * c0 * v, 0.02),
          absolute("kinetic_energy_lost", 1 - sim->energy().current().kinetic / kinetic0, 0, 0.01)};
}

// ------------------------------------------------------------------------------------------------
// 3. Tet–tet impact (Munjiza 2004)
// ------------------------------------------------------------------------------------------------
namespace {

BodyMesh single_tet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  BodyMesh m;
  m.source = "verification";
  for (const Vec3* p : {&a, &b, &c, &d}) m.coords.insert(m.coords.end(), {p->x(), p->y(), p->z()});
  m.tets = {0, 1, 2, 3};
  Vec3 X[4] = {a, b, c, d};
  if (tet_reference(X).volume < 0) std::swap(m.tets[2], m.tets[3]);
  return m;
}

}  // namespace

std::vector<Measure> tet_tet_impact(const Setting& s) {
  const double a = 1.34, E = 100e9;
  const Vec3 dir = -Vec3(1, 1, 1).normalized();
  std::vector<Measure> out;
  for (bool fixed : {true, false}) {
    Scene scene = basic_scene(6e-4, s.dt_fraction);
    scene.materials.push_back(elastic_material(1500, E, 0.0));
    set_penalty(scene.materials[0], s.penalty_ratio);
    scene.bodies.push_back(box_body("target", Vec3::Zero(), Vec3::Ones(), 1, 1, 1));
    scene.bodies.push_back(box_body("contactor", Vec3::Zero(), Vec3::Ones(), 1, 1, 1));
    scene.bodies[0].fixed = fixed;
    scene.bodies[1].velocity = 550.0 * dir;
    std::vector<BodyMesh> meshes = {
        single_tet(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(0, 0, 2)),
        single_tet(Vec3(a, a, a), Vec3(a - 2, a, a), Vec3(a, a - 2, a), Vec3(a, a, a - 2))};
    Simulation sim(scene, build_model(scene, meshes), quiet_options());
    sim.step();
    const Vec3 p0 = linear_momentum(sim.model().nodes);
    double worst_energy = 0, worst_momentum = 0;
    while (sim.time() < scene.time.end) {
      sim.step();
      worst_energy = std::max(worst_energy, sim.energy().balance_error());
      if (!fixed)
        worst_momentum =
            std::max(worst_momentum, (linear_momentum(sim.model().nodes) - p0).norm() / p0.norm());
    }
    if (fixed) {
      out.push_back(absolute("energy_error_fixed_target", worst_energy, 0, 1e-3));
    } else {
      out.push_back(absolute("energy_error_free_target", worst_energy, 0, 1e-3));
      out.push_back(absolute("momentum_drift_free_target", worst_momentum, 0, 1e-12));
    }
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// 4b. Free spinning cube
// ------------------------------------------------------------------------------------------------
std::vector<Measure> spinning_cube(const Setting& s) {
  Scene scene = basic_scene(2 * M_PI / 10, s.dt_fraction);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.2));
  const int n = cells_for(1.0, s.h);
  scene.bodies.push_back(box_body("cube", Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5), n, n, n));
  scene.bodies[0].angular_velocity = 10.0 * Vec3(1, 1, 1).normalized();
  auto sim = quiet_simulation(scene);
  sim->step();
  const Vec3 L0 = angular_momentum(sim->model().nodes);
  const double K0 = sim->energy().current().kinetic;
  double worst_L = 0, worst_K = 0;
  while (sim->time() < scene.time.end) {
    sim->step();
    worst_L = std::max(worst_L, (angular_momentum(sim->model().nodes) - L0).norm() / L0.norm());
    worst_K = std::max(worst_K, std::abs(sim->energy().current().kinetic - K0) / K0);
  }
  return {absolute("angular_momentum_drift", worst_L, 0, 1e-10),
          absolute("kinetic_energy_drift", worst_K, 0, 1e-4)};
}

// ------------------------------------------------------------------------------------------------
// 5. Beam frequencies: free–free axial and free–free bending
// ------------------------------------------------------------------------------------------------
std::vector<Measure> axial_frequency(const Setting& s) {
  const double L = 2.0, E = 30e9, rho = 2500;
  const double f_exact = std::sqrt(E / rho) / (2 * L);  // 866.0 Hz
  Scene scene = basic_scene(3.2 / f_exact, s.dt_fraction);
  scene.materials.push_back(elastic_material(rho, E, 0.0, ElasticModel::st_venant_kirchhoff));
  const int n = cells_for(0.1, s.h);
  scene.bodies.push_back(
      box_body("beam", Vec3(0, 0, 0), Vec3(L, 0.1, 0.1), cells_for(L, s.h), n, n));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    model.nodes.v[3 * i] = 0.01 * std::cos(M_PI * model.nodes.x0(i)[0] / L);
  CrossingCounter crossings;
  while (sim->time() < scene.time.end) {
    sim->step();
    if (sim->steps_done() > 2)
      crossings.add(sim->time(), face_position(model, 0, 0, L) - face_position(model, 0, 0, 0) - L);
  }
  return {relative("axial_frequency", crossings.frequency(), f_exact, 0.01)};
}

// First free–free bending mode of a 2.0 × 0.1 × 0.1 m beam (Euler–Bernoulli): β₁L = 4.7300.
// Tetrahedra with linear shape functions lock in bending: the error against h is the result.
std::vector<Measure> bending_frequency(const Setting& s) {
  const double L = 2.0, a = 0.1, E = 30e9, rho = 2500;
  const double beta = 4.730040745 / L;
  const double f_exact = beta * beta / (2 * M_PI) * std::sqrt(E * a * a / (12 * rho));  // 89.0 Hz
  Scene scene = basic_scene(3.0 / f_exact, s.dt_fraction);
  scene.materials.push_back(elastic_material(rho, E, 0.0, ElasticModel::st_venant_kirchhoff));
  const int n = cells_for(a, s.h);
  scene.bodies.push_back(box_body("beam", Vec3(0, 0, 0), Vec3(L, a, a), cells_for(L, s.h), n, n));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  // Mode shape φ(x) = cosh βx + cos βx − σ(sinh βx + sin βx) as the initial velocity along z.
  const double bl = beta * L;
  const double sigma = (std::cosh(bl) - std::cos(bl)) / (std::sinh(bl) - std::sin(bl));
  for (LocalIndex i = 0; i < model.nodes.size(); ++i) {
    const double x = beta * model.nodes.x0(i)[0];
    model.nodes.v[3 * i + 2] =
        1e-3 * (std::cosh(x) + std::cos(x) - sigma * (std::sinh(x) + std::sin(x)));
  }
  CrossingCounter crossings;  // mid-span deflection against the ends' mean
  while (sim->time() < scene.time.end) {
    sim->step();
    double zm = 0, ze = 0;
    int nm = 0, ne = 0;
    for (LocalIndex i = 0; i < model.nodes.size(); ++i) {
      const double X = model.nodes.x0(i)[0], u = model.nodes.x[3 * i + 2] - model.nodes.x0(i)[2];
      if (std::abs(X - L / 2) < 1e-9) zm += u, ++nm;
      if (X == 0 || X == L) ze += u, ++ne;
    }
    crossings.add(sim->time(), zm / nm - ze / ne);
  }
  return {relative("bending_frequency", crossings.frequency(), f_exact, 0.05)};
}

}  // namespace fdem::verification_suite
