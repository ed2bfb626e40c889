// Verification suite: every reference problem of the design notes (docs/references.md) that the
// engine supports, run at several mesh sizes h, time-step fractions Δt/Δt_crit and penalty ratios
// p/E. Each run records its wall time and the error of each measured quantity against its reference
// value, with the pass/fail tolerance of that quantity: the "run time against error" curves of
// docs/verification.md.
//
// Sweeps: every problem has a base setting (its finest: the most accurate one the suite runs) and
// varies one parameter at a time from it; the CSV's `sweep` column says which (base rows belong to
// every series).  --quick runs one setting per problem: the coarsest mesh of its sweep at the
// base step and penalty.
//
// Usage: bench_verification [--quick] [--csv PATH] [--only NAME[,NAME...]] [--list]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
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

using namespace fdem;
using namespace fdem::builders;

namespace {

// ------------------------------------------------------------------------------------------------
// Suite plumbing
// ------------------------------------------------------------------------------------------------

// One point of a sweep.  h: characteristic element size (m; 0 where the mesh is fixed),
// dt_fraction: Δt/Δt_crit (time.safety), penalty_ratio: contact penalty p/E (0: not used).
struct Setting {
  double h = 0, dt_fraction = 0.5, penalty_ratio = 0;
};

// A measured quantity: `error` is what the tolerance applies to (relative error, or an absolute
// error for quantities whose reference is 0, such as drifts and balance errors).
struct Measure {
  std::string quantity;
  double value = 0, reference = 0, error = 0, tolerance = 0;
};

Measure relative(const std::string& q, double value, double reference, double tolerance) {
  return {q, value, reference, std::abs(value - reference) / std::abs(reference), tolerance};
}
Measure absolute(const std::string& q, double value, double reference, double tolerance) {
  return {q, value, reference, std::abs(value - reference), tolerance};
}

struct Problem {
  std::string name;       // short id, used in file names
  std::string reference;  // docs/references.md item
  Setting base;
  std::vector<double> h, dt_fraction, penalty_ratio;  // the values swept (besides the base)
  std::function<std::vector<Measure>(const Setting&)> run;
};

struct Row {
  std::string problem, sweep;
  Setting setting;
  double wall = 0;
  Measure m;
  bool pass() const { return std::isfinite(m.error) && m.error <= m.tolerance; }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ------------------------------------------------------------------------------------------------
// Scene helpers: drivers/scene_builders.hpp (shared with the verification tests), and these
// ------------------------------------------------------------------------------------------------

void set_penalty(MaterialSpec& m, double penalty_ratio) {
  if (penalty_ratio <= 0) return;  // automatic (10 E)
  m.contact.auto_penalty = false;
  m.contact.penalty = penalty_ratio * m.elastic.young;
}

Scene basic_scene(double end_time, double dt_fraction) {
  Scene s = builders::basic_scene(end_time);
  s.time.safety = dt_fraction;
  return s;
}

int cells_for(double length, double h) {
  return std::max(1, int(std::lround(length / h)));
}

// Mean of coordinate k of the nodes of `body` whose reference coordinate k equals `at` (m).
double face_position(const Model& model, int body, int k, double at, bool displacement = false) {
  double sum = 0;
  int n = 0;
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    if (model.pieces[model.nodes.piece[i]].body == body &&
        std::abs(model.nodes.x0(i)[k] - at) < 1e-9) {
      sum += model.nodes.x[3 * i + k] - (displacement ? model.nodes.x0(i)[k] : 0.0);
      ++n;
    }
  return sum / n;
}

// Zero crossings of a sampled signal, linearly interpolated (s).
struct CrossingCounter {
  std::vector<double> times;
  double previous = 0, previous_time = 0;
  bool started = false;
  void add(double t, double value) {
    if (started && (value < 0) != (previous < 0) && previous != value)
      times.push_back(previous_time + (t - previous_time) * previous / (previous - value));
    previous = value;
    previous_time = t;
    started = true;
  }
  // Frequency from the mean spacing of crossings (two per period), Hz; 0 if too few.
  double frequency() const {
    if (times.size() < 3) return 0;
    return 0.5 * (times.size() - 1) / (times.back() - times.front());
  }
};

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
BodyMesh single_tet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  BodyMesh m;
  m.source = "verification";
  for (const Vec3* p : {&a, &b, &c, &d}) m.coords.insert(m.coords.end(), {p->x(), p->y(), p->z()});
  m.tets = {0, 1, 2, 3};
  Vec3 X[4] = {a, b, c, d};
  if (tet_reference(X).volume < 0) std::swap(m.tets[2], m.tets[3]);
  return m;
}

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
FractureSpec rock_fracture() {
  FractureSpec f;
  f.tensile_strength = 5e6;
  f.cohesion = 10e6;
  f.friction_angle_deg = 30;
  f.energy_I = 50;
  f.energy_II = 250;
  return f;
}

Scene two_block_scene(double L, double w, int cells_x, int cells_yz, const FractureSpec& f,
                      double end_time, double dt_fraction) {
  Scene scene = basic_scene(end_time, dt_fraction);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.0));
  scene.bodies.push_back(box_body("a", Vec3(0, 0, 0), Vec3(L, w, w), cells_x, cells_yz, cells_yz));
  scene.bodies.push_back(
      box_body("b", Vec3(L, 0, 0), Vec3(2 * L, w, w), cells_x, cells_yz, cells_yz));
  InterfaceSpec joint;
  joint.body_a = 0;
  joint.body_b = 1;
  joint.fracture = f;
  scene.interfaces.push_back(joint);
  return scene;
}

std::vector<Measure> cohesive_layer(const Setting& s) {
  const double L = 0.1, w = 0.05, v = 0.01;
  const FractureSpec f = rock_fracture();
  Scene scene =
      two_block_scene(L, w, cells_for(L, s.h), cells_for(w, s.h), f, 10e-3, s.dt_fraction);
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
struct ShearRun {
  double peak = 0, sigma_at_peak = 0, final_shear = 0;
};

ShearRun rigid_shear(const FractureSpec& f, double L, double w, int cells_x, int cells_yz,
                     double sigma, double slide, double v, double dt_fraction) {
  Scene scene = two_block_scene(L, w, cells_x, cells_yz, f, 1.0, dt_fraction);
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

// ------------------------------------------------------------------------------------------------
// The problems and their sweeps
// ------------------------------------------------------------------------------------------------
std::vector<Problem> problems() {
  std::vector<Problem> p;
  // name, reference, base {h, dt_fraction, penalty_ratio}, h sweep, dt sweep, penalty sweep, run
  p.push_back({"stopped_bar",
               "1",
               {0.02 / 160, 0.9, 0},
               {0.02 / 40, 0.02 / 80},
               {0.3, 0.6},
               {},
               stopped_bar});
  p.push_back({"two_bar_impact",
               "2",
               {0.5 / 200, 0.5, 10},
               {0.5 / 50, 0.5 / 100},
               {0.25},
               {1, 100},
               two_bar_impact});
  p.push_back({"tet_tet_impact", "3", {0, 0.05, 10}, {}, {0.1, 0.2}, {1, 100}, tet_tet_impact});
  p.push_back(
      {"spinning_cube", "4b", {1.0 / 8, 0.45, 0}, {1.0 / 2, 1.0 / 4}, {0.9}, {}, spinning_cube});
  p.push_back(
      {"axial_frequency", "5", {0.025, 0.45, 0}, {0.1, 0.05}, {0.7, 0.9}, {}, axial_frequency});
  p.push_back({"bending_frequency",
               "5",
               {0.0125, 0.9, 0},
               {0.1, 0.05, 0.025},
               {0.45},
               {},
               bending_frequency});
  p.push_back({"incline", "6", {0.125, 0.5, 10}, {0.5, 0.25}, {0.9}, {100}, incline});
  p.push_back({"oblique_impact", "7", {0.05, 0.5, 10}, {0.2, 0.1}, {0.25}, {100}, oblique_impact});
  p.push_back(
      {"stacked_blocks", "8", {0.1, 0.5, 100}, {}, {0.25, 0.9}, {3, 10, 30}, stacked_blocks});
  p.push_back({"cohesive_layer", "10", {0.025, 0.35, 0}, {0.1, 0.05}, {0.7}, {}, cohesive_layer});
  p.push_back({"dry_joint_shear", "12", {0.05, 0.35, 0}, {0.1}, {0.7}, {}, dry_joint_shear});
  p.push_back({"uniaxial_compression",
               "14",
               {0.05, 0.5, 10},
               {0.1, 0.025},
               {0.9},
               {1, 30},
               uniaxial_compression});
  return p;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, list = false;
  std::string csv_path = "verification.csv";
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick")
      quick = true;
    else if (arg == "--list")
      list = true;
    else if (arg == "--csv" && i + 1 < argc)
      csv_path = argv[++i];
    else if (arg == "--only" && i + 1 < argc)
      only = split(argv[++i], ',');
    else {
      std::cerr << "usage: bench_verification [--quick] [--csv PATH] [--only NAME[,NAME...]] "
                   "[--list]\n";
      return 2;
    }
  }
  const std::vector<Problem> all = problems();
  if (list) {
    for (const Problem& p : all)
      std::cout << p.name << " (docs/references.md " << p.reference << ")\n";
    return 0;
  }
  std::ofstream csv(csv_path);
  if (!csv) {
    std::cerr << "cannot write " << csv_path << "\n";
    return 2;
  }
  csv << "problem,quantity,h,dt_fraction,penalty_ratio,wall_seconds,value,reference,error,"
         "tolerance,pass,sweep\n";
  csv.precision(10);
  std::printf("%-22s %-8s %-34s %9s %6s %6s %8s %12s %12s %10s %9s %s\n", "problem", "sweep",
              "quantity", "h (m)", "dt/dtc", "p/E", "wall s", "value", "reference", "error",
              "tolerance", "pass");
  int failed_runs = 0;
  for (const Problem& problem : all) {
    if (!only.empty() && std::find(only.begin(), only.end(), problem.name) == only.end()) continue;
    // (sweep name, setting): base first, then one parameter at a time.
    std::vector<std::pair<std::string, Setting>> runs;
    auto add_series = [&](const std::string& name, const std::vector<double>& values,
                          double Setting::*field) {
      for (double value : values) {
        Setting s = problem.base;
        s.*field = value;
        runs.push_back({name, s});
      }
    };
    if (quick) {  // the cheap end: coarsest mesh of the sweep, base step and penalty
      Setting s = problem.base;
      for (double h : problem.h) s.h = std::max(s.h, h);
      runs.push_back({"quick", s});
    } else {
      runs.push_back({"base", problem.base});
      add_series("h", problem.h, &Setting::h);
      add_series("dt_fraction", problem.dt_fraction, &Setting::dt_fraction);
      add_series("penalty_ratio", problem.penalty_ratio, &Setting::penalty_ratio);
    }
    for (const auto& [sweep, setting] : runs) {
      std::vector<Measure> measures;
      const auto t0 = std::chrono::steady_clock::now();
      std::string failure;
      try {
        measures = problem.run(setting);
      } catch (const std::exception& e) {
        failure = e.what();
      }
      const double wall = seconds_since(t0);
      if (!failure.empty()) {
        ++failed_runs;
        std::printf("%-22s %-8s run failed after %.1f s: %s\n", problem.name.c_str(), sweep.c_str(),
                    wall, failure.c_str());
        measures.push_back({"run_failed", std::nan(""), 0, std::nan(""), 0});
      }
      for (const Measure& m : measures) {
        Row row{problem.name, sweep, setting, wall, m};
        std::printf("%-22s %-8s %-34s %9.3g %6.3g %6.3g %8.2f %12.5g %12.5g %10.3g %9.3g %s\n",
                    problem.name.c_str(), sweep.c_str(), m.quantity.c_str(), setting.h,
                    setting.dt_fraction, setting.penalty_ratio, wall, m.value, m.reference, m.error,
                    m.tolerance, row.pass() ? "yes" : "NO");
        csv << problem.name << ',' << m.quantity << ',' << setting.h << ',' << setting.dt_fraction
            << ',' << setting.penalty_ratio << ',' << wall << ',' << m.value << ',' << m.reference
            << ',' << m.error << ',' << m.tolerance << ',' << (row.pass() ? "yes" : "no") << ','
            << sweep << '\n';
      }
      std::fflush(stdout);
      csv.flush();
    }
  }
  return failed_runs > 0 ? 1 : 0;
}
