// Verification suite: friction, contact stacks, cohesive joints and compression (docs/references.md
// items 6–8, 10, 12, 14).
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
// 6. Block on an incline (gravity tilted by the slope angle)
// ------------------------------------------------------------------------------------------------
std::vector<Measure> incline(const Setting& s) {
  const double psi = 40 * M_PI / 180, phi = 20 * M_PI / 180, g = 10.0, end_time = 0.6;
  const double expected = g * (std::sin(psi) - std::cos(psi) * std::tan(phi));  // 3.640 m/s²
  Scene scene = basic_scene(end_time, s.dt_fraction);
  scene.gravity = g * Vec3(std::sin(psi), 0, -std::cos(psi));
  scene.materials.push_back(elastic_material(2000, 5e7, 0.2));
  scene.materials[0].contact.friction = std::tan(phi);
  set_penalty(scene.materials[0], s.penalty_ratio);
  const int n = cells_for(0.5, s.h);
  scene.bodies.push_back(box_body("base", Vec3(-0.5, -0.5, -0.2), Vec3(3.5, 0.5, 0), 8 * n, 2 * n,
                                  std::max(1, n / 2)));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(
      box_body("block", Vec3(0, -0.25, 0), Vec3(0.5, 0.25, 0.25), n, n, std::max(1, n / 2)));
  auto sim = quiet_simulation(scene);
  std::vector<double> t, x;
  while (sim->time() < end_time) {
    sim->step();
    if (sim->steps_done() % 50 == 0) {
      t.push_back(sim->time());
      x.push_back(piece_motions(sim->model())[1].centroid.x() - 0.25);
    }
  }
  // s = s0 + v0 t + a t²/2 fitted over the second half (after the settling transient).
  const std::size_t first = t.size() - t.size() / 2, rows = t.size() / 2;
  Eigen::MatrixXd A(rows, 3);
  Eigen::VectorXd b(rows);
  for (std::size_t i = first, r = 0; i < t.size(); ++i, ++r) {
    A(r, 0) = 1;
    A(r, 1) = t[i];
    A(r, 2) = 0.5 * t[i] * t[i];
    b(r) = x[i];
  }
  const Eigen::Vector3d fit = A.colPivHouseholderQr().solve(b);
  const double normal = sim->model().pieces[1].mass * g * std::cos(psi);
  return {relative("acceleration", fit(2), expected, 0.01),
          relative("friction_dissipation", sim->energy().current().dissipated_friction,
                   std::tan(phi) * normal * x.back(), 0.02),
          absolute("energy_balance", sim->energy().balance_error(), 0, 0.01)};
}

// ------------------------------------------------------------------------------------------------
// 7. Oblique impact in gross slip
// ------------------------------------------------------------------------------------------------
std::vector<Measure> oblique_impact(const Setting& s) {
  const double mu = 0.1;
  Scene scene = basic_scene(0.02, s.dt_fraction);
  scene.materials.push_back(elastic_material(2000, 1e8, 0.2));
  scene.materials[0].contact.friction = mu;
  set_penalty(scene.materials[0], s.penalty_ratio);
  const int n = cells_for(0.2, s.h);
  scene.bodies.push_back(
      box_body("base", Vec3(-0.5, -0.5, -0.1), Vec3(0.5, 0.5, 0), 5 * n / 2, 5 * n / 2, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(
      box_body("block", Vec3(-0.1, -0.1, 0.001), Vec3(0.1, 0.1, 0.201), n, n, n));
  scene.bodies[1].velocity = Vec3(1, 0, -1);
  auto sim = quiet_simulation(scene);
  while (sim->time() < scene.time.end) sim->step();
  const Vec3 v = piece_motions(sim->model())[1].velocity;
  const double e = v.z(), e_t = v.x();
  return {relative("tangential_restitution", e_t, 1 - mu * (1 + e), 0.03)};
}

// ------------------------------------------------------------------------------------------------
// 8. Stacked blocks under a slowly pushed top face
// ------------------------------------------------------------------------------------------------
std::vector<Measure> stacked_blocks(const Setting& s) {
  const double a = 0.1, E = 1e9, rho = 1000, v = 0.005;
  const double p = s.penalty_ratio * E;
  const int n = cells_for(a, s.h);
  const double cell = a / n;
  Scene scene = basic_scene(0.03, s.dt_fraction);
  scene.materials.push_back(elastic_material(rho, E, 0.0, ElasticModel::st_venant_kirchhoff));
  set_penalty(scene.materials[0], s.penalty_ratio);
  scene.materials[0].damping = 0.3;
  scene.materials[0].contact.damping = 0.3;
  scene.bodies.push_back(
      box_body("base", Vec3(-0.1, -0.1, -a), Vec3(0.2, 0.2, 0), 3 * n, 3 * n, 1));
  scene.bodies[0].fixed = true;
  for (int i = 0; i < 3; ++i)
    scene.bodies.push_back(
        box_body("block" + std::to_string(i), Vec3(0, 0, i * a), Vec3(a, a, (i + 1) * a), n, n, n));
  scene.loads.push_back(
      load_on_region(Vec3(-1, -1, 3 * a - 1e-9), Vec3(1, 1, 3 * a + 1e-9), Vec3(0, 0, -v), 4));
  auto sim = quiet_simulation(scene);
  while (sim->time() < scene.time.end) sim->step();
  double force = 0;
  for (const ContactRecord& r : sim->contact_stage()->records())
    if (std::abs(r.point.z() - 2 * a) < 0.25 * cell) force += std::abs(r.normal_force.z());
  const double sigma = force / (a * a);
  // Each interface between cells of height `cell` closes σ·cell/(8p) (tests/verification).
  const double predicted = sigma * (3 * a / E + 3 * cell / (8 * p));
  return {relative("shortening", v * sim->time(), predicted, 0.03)};
}

// ------------------------------------------------------------------------------------------------
// 10. Cohesive layer in tension: two-block bar pulled apart through the whole engine
// ------------------------------------------------------------------------------------------------
std::vector<Measure> cohesive_layer(const Setting& s) {
  const double L = 0.1, w = 0.05, v = 0.01;
  const FractureSpec f = rock_fracture();
  Scene scene = two_block_scene(L, w, cells_for(L, s.h), cells_for(w, s.h), f, 10e-3);
  scene.time.safety = s.dt_fraction;
  scene.loads.push_back(load_on_region(Vec3(-1, -1, -1), Vec3(1e-9, 1, 1), Vec3(-v / 2, 0, 0)));
  scene.loads.push_back(
      load_on_region(Vec3(2 * L - 1e-9, -1, -1), Vec3(1, 1, 1), Vec3(v / 2, 0, 0)));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  double peak = 0, worst_balance = 0;
  while (sim->time() < scene.time.end) {
    sim->step();
    peak = std::max(peak, reaction_on_body(model, 1).x() / (w * w));
    worst_balance = std::max(worst_balance, sim->energy().balance_error());
  }
  return {relative("dissipated_energy_per_area",
                   sim->energy().current().dissipated_fracture / (w * w), f.energy_I, 0.005),
          relative("peak_stress", peak, f.tensile_strength, 0.02),
          absolute("unbroken_joint_fraction",
                   1.0 - double(broken_joints(model)) / model.joints.size(), 0, 0),
          absolute("energy_balance", worst_balance, 0, 0.01)};
}

// ------------------------------------------------------------------------------------------------
// 12. Dry-joint shear (Smoljanović et al. 2013): block a fixed, block b pressed then slid
// ------------------------------------------------------------------------------------------------
namespace {

struct ShearRun {
  double peak = 0, sigma_at_peak = 0, final_shear = 0;
};

ShearRun rigid_shear(const FractureSpec& f, double L, double w, int cells_x, int cells_yz,
                     double sigma, double slide, double v, double dt_fraction) {
  Scene scene = two_block_scene(L, w, cells_x, cells_yz, f, 1.0);
  scene.time.safety = dt_fraction;
  scene.bodies[0].fixed = true;
  scene.materials[0].contact.friction = std::tan(f.friction_angle_deg * M_PI / 180);
  scene.contact_buffer = 2e-4;
  scene.loads.push_back(load_on_body(1, Vec3::Zero()));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  const double area = w * w, dt = sim->time_step();
  const CohesiveLaw& law = sim->joint_stage()->laws().at(0);
  const int press_steps = 100;
  const double half = 0.5 * sigma / law.normal_stiffness();
  set_body_velocity(model, 1, Vec3(-half / (press_steps * dt), 0, 0));
  for (int i = 0; i < press_steps; ++i) sim->step();
  set_body_velocity(model, 1, Vec3::Zero());
  sim->step();
  const double measured = -reaction_on_body(model, 1).x() / area;
  set_body_velocity(model, 1, Vec3(-half * (sigma / measured - 1) / (press_steps * dt), 0, 0));
  for (int i = 0; i < press_steps; ++i) sim->step();
  set_body_velocity(model, 1, Vec3(0, v, 0));
  ShearRun out;
  const long slide_steps = std::lround(slide / (v * dt));
  for (long i = 0; i < slide_steps; ++i) {
    sim->step();
    if (i == 0) continue;
    const Vec3 r = reaction_on_body(model, 1);
    const double tau = r.y() / area, sig = -r.x() / area;
    if (broken_joints(model) == 0 && tau > out.peak) {
      out.peak = tau;
      out.sigma_at_peak = sig;
    }
    out.final_shear = tau;
  }
  return out;
}

}  // namespace

std::vector<Measure> dry_joint_shear(const Setting& s) {
  FractureSpec dry;
  dry.tensile_strength = 1e3;
  dry.energy_I = 1.0;
  dry.cohesion = 0.0;
  dry.friction_angle_deg = std::atan(0.65) * 180 / M_PI;
  std::vector<Measure> out;
  for (double sigma : {0.25e6, 0.5e6, 1.0e6}) {
    const ShearRun r = rigid_shear(dry, 0.1, 0.2, cells_for(0.1, s.h), cells_for(0.2, s.h), sigma,
                                   0.5e-3, 0.5, s.dt_fraction);
    char name[64];
    std::snprintf(name, sizeof name, "peak_over_mu_sigma_%.2fMPa", sigma / 1e6);
    out.push_back(relative(name, r.peak / (0.65 * r.sigma_at_peak), 1.0, 0.02));
    std::snprintf(name, sizeof name, "residual_over_peak_%.2fMPa", sigma / 1e6);
    out.push_back(relative(name, r.final_shear / r.peak, 1.0, 0.02));
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// 14. Uniaxial compression between frictionless platens
// ------------------------------------------------------------------------------------------------
// A 0.1 × 0.1 × 0.2 m prism (E = 30 GPa, ν = 0.2, ρ = 2500) between two steel-like platens wider
// than it; the lower platen is fixed, the upper one pushed down at a speed that rises smoothly
// (sin² over 8 P-wave transits of the prism) to 0.02 m/s, 20 transits in all.  Friction 0: the
// prism expands freely, so the state is uniform and E = σ/ε_z, ν = −ε_x/ε_z hold for any mesh.  σ
// from the platen's reaction; strains from the mean displacement of the prism's own faces (a
// strain-gauge measurement: the platens' contact compliance does not enter).  E and ν are the
// least-squares slopes over the run's second half (σ against ε_z, ε_x against ε_z).
std::vector<Measure> uniaxial_compression(const Setting& s) {
  const double E = 30e9, nu = 0.2, rho = 2500, a = 0.1, H = 0.2, t_platen = 0.02, v = 0.02;
  const double c_p = std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
  const double transit = H / c_p, ramp = 8 * transit, end_time = 20 * transit;
  Scene scene = basic_scene(end_time, s.dt_fraction);
  // St. Venant–Kirchhoff: its energy at F = I is exactly 0, while the neo-Hookean one is ~1e-16·E
  // per unit volume of round-off, which the energy check would compare with the first tiny loads.
  scene.materials.push_back(elastic_material(rho, E, nu, ElasticModel::st_venant_kirchhoff));
  set_penalty(scene.materials[0], s.penalty_ratio);
  scene.materials[0].contact.friction = 0.0;
  const int n = cells_for(a, s.h), nz = cells_for(H, s.h);
  const double overhang = 0.02;
  scene.bodies.push_back(box_body("lower_platen", Vec3(-overhang, -overhang, -t_platen),
                                  Vec3(a + overhang, a + overhang, 0), n + 2, n + 2, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(box_body("prism", Vec3(0, 0, 0), Vec3(a, a, H), n, n, nz));
  scene.bodies.push_back(box_body("upper_platen", Vec3(-overhang, -overhang, H),
                                  Vec3(a + overhang, a + overhang, H + t_platen), n + 2, n + 2, 1));
  scene.loads.push_back(load_on_body(2, Vec3::Zero()));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  std::vector<double> strain_z, strain_x, stress;
  while (sim->time() < end_time) {
    const double t = sim->time() + 0.5 * sim->time_step();  // velocity of the coming half step
    const double ramp_factor = t < ramp ? std::pow(std::sin(0.5 * M_PI * t / ramp), 2) : 1.0;
    set_body_velocity(model, 2, Vec3(0, 0, -v * ramp_factor));
    sim->step();
    if (sim->time() < 0.5 * end_time) continue;
    const double ez = (face_position(model, 1, 2, H) - face_position(model, 1, 2, 0)) / H - 1;
    const double ex = (face_position(model, 1, 0, a) - face_position(model, 1, 0, 0)) / a - 1;
    strain_z.push_back(ez);
    strain_x.push_back(ex);
    stress.push_back(reaction_on_body(model, 2).z() / (a * a));  // the device pushes down: < 0
  }
  auto slope = [](const std::vector<double>& x, const std::vector<double>& y) {
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / x.size(), my += y[i] / x.size();
    double sxy = 0, sxx = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
    return sxy / sxx;
  };
  return {relative("apparent_young_modulus", slope(strain_z, stress), E, 0.01),
          relative("apparent_poisson_ratio", -slope(strain_z, strain_x), nu, 0.01)};
}

}  // namespace fdem::verification_suite
