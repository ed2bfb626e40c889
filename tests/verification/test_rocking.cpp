// Free rocking of a rigid block (docs/references.md 13, Housner 1963): a block set rocking about
// its toe with angular velocity ω0 rises to θmax and comes back down on its base at the time the
// rigid-block equation θ'' = −p² sin(α − θ) gives (p² = 3g/(4R) for a rectangular block, R its
// half-diagonal, α = atan(b/h)); the impact on its heel keeps the share of its angular velocity
// that the conservation of angular momentum about the heel gives (1 − 1.5 sin²α for a continuum).
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>

#include "core/dynamics.hpp"
#include "core/piece_moments.hpp"
#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

struct RigidRocking {
  double return_time = 0;  // s: θ back to 0
  double max_angle = 0;    // rad
};

// θ'' = −p² sin(α − θ) from θ = 0, θ' = ω0 (RK4, 1 µs steps) until θ is back to 0.
RigidRocking rigid_rocking(double p, double alpha, double omega0) {
  const double dt = 1e-6;
  const auto accel = [&](double theta) { return -p * p * std::sin(alpha - theta); };
  double theta = 0, omega = omega0, t = 0;
  RigidRocking r;
  while (true) {
    const double k1x = omega, k1v = accel(theta);
    const double k2x = omega + 0.5 * dt * k1v, k2v = accel(theta + 0.5 * dt * k1x);
    const double k3x = omega + 0.5 * dt * k2v, k3v = accel(theta + 0.5 * dt * k2x);
    const double k4x = omega + dt * k3v, k4v = accel(theta + dt * k3x);
    const double next = theta + dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    omega += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (next <= 0 && theta > 0) {
      r.return_time = t + dt * theta / (theta - next);
      return r;
    }
    theta = next;
    t += dt;
    r.max_angle = std::max(r.max_angle, theta);
  }
}

}  // namespace

TEST_CASE(
    "a block set rocking about its toe comes back onto its base when the rigid-block "
    "equation says, within 1 %, and keeps Housner's share of its angular velocity in the impact, "
    "within 1 % (docs/references.md 13)",
    "[verification][masonry]") {
  // Block 0.25 × 0.2 × 1.0 m (b/h = 0.25) on a fixed base, μ = 0.8 (no sliding at the toe).
  const double b = 0.25, h = 1.0, g = 9.81, young = 1e9;
  const double R = 0.5 * std::hypot(b, h), alpha = std::atan(b / h);
  const double p = std::sqrt(3 * g / (4 * R));
  const double omega0 = 0.5 * p * alpha;
  const RigidRocking continuum = rigid_rocking(p, alpha, omega0);

  Scene scene = block_on_base(b, h, 0.8, 2.5 * continuum.return_time, young);
  scene.gravity = Vec3(0, 0, -g);
  BodySpec& block = scene.bodies[1];
  // Rigid rotation about the toe edge (x = b/2, z = 0, along y): ω × (x − toe) = ω × (x − c) +
  // ω × (c − toe), the centroid c = (0, 0, h/2).
  block.angular_velocity = Vec3(0, omega0, 0);
  block.velocity = Vec3(0, omega0, 0).cross(Vec3(-0.5 * b, 0, 0.5 * h));

  auto sim = quiet_simulation(scene);
  // The rigid-block equation with the model's own mass moments about the toe: lumped nodal
  // masses put more of the mass at the faces than a continuum (2 cells across: I about the
  // centroid is m(b²/8 + h²/12·(1 + 2/8²)), not m(b² + h²)/12), so the reference uses the
  // discrete inertia; the continuum's return time is printed beside it.
  const Model& model = sim->model();
  double mass = 0, inertia = 0;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.piece[n] != 1) continue;
    const Vec3 r = model.nodes.x0(n) - Vec3(0.5 * b, 0, 0);
    mass += model.nodes.mass[n];
    inertia += model.nodes.mass[n] * (r.x() * r.x() + r.z() * r.z());
  }
  const double p_model = std::sqrt(mass * g * R / inertia);
  const RigidRocking rigid = rigid_rocking(p_model, alpha, omega0);
  const auto clock = std::chrono::steady_clock::now();
  double theta = 0, previous = 0, max_angle = 0, landed = -1, min_angle = 0, back = -1;
  long steps = 0;
  while (sim->time() < scene.time.end - 1e-12 && back < 0) {
    sim->step();
    ++steps;
    theta = piece_motions(sim->model())[1].rotation.y();
    if (landed < 0) max_angle = std::max(max_angle, theta);
    if (landed < 0 && theta <= 0 && previous > 0 && max_angle > 0.1 * alpha)
      landed = sim->time() - sim->time_step() * theta / (theta - previous);
    if (landed > 0) min_angle = std::min(min_angle, theta);
    if (landed > 0 && theta >= 0 && previous < 0) back = sim->time();
    previous = theta;
  }
  // The impact: about the heel the angular momentum before is ω(I_c + m R² cos 2α), after
  // ω'(I_c + m R²) = ω' I_heel, so ω'/ω = 1 − 2 m R² sin²α / I_heel (with the continuum's
  // I_heel = 4/3 m R²: Housner's 1 − 1.5 sin²α).  The angular velocities on the base, before
  // and after, follow from the heights of the swings by the rigid block's energy,
  // ω² = 2 p² (cos(α − |θ|max) − cos α).
  const double housner = 1 - 2 * mass * R * R * std::sin(alpha) * std::sin(alpha) / inertia;
  const auto omega_on_base = [&](double amplitude) {
    return std::sqrt(2 * p_model * p_model * (std::cos(alpha - amplitude) - std::cos(alpha)));
  };
  const double ratio = omega_on_base(-min_angle) / omega_on_base(max_angle);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  INFO("continuum block: back at " << continuum.return_time << " s, θmax " << continuum.max_angle
                                   << " rad; lumped masses: p " << p_model << " against " << p);
  INFO("rigid block: back on its base at " << rigid.return_time << " s, θmax " << rigid.max_angle
                                           << " rad; fdem: " << landed << " s, θmax " << max_angle
                                           << " rad (" << steps << " steps, " << wall << " s)");
  INFO("impact: the next swing reaches " << min_angle << " rad, angular velocity ratio " << ratio
                                         << " against " << housner << " (continuum "
                                         << 1 - 1.5 * std::sin(alpha) * std::sin(alpha) << ")");
  CHECK(landed > 0);
  CHECK(back > 0);
  // Measured: +0.5 % and +0.7 % (E = 1e9 Pa); with E = 1e8 Pa the block's own sway adds +1.8 %
  // and +2.8 %.
  CHECK(std::abs(landed - rigid.return_time) < 0.01 * rigid.return_time);
  CHECK(std::abs(max_angle - rigid.max_angle) < 0.01 * rigid.max_angle);
  // Measured: 0.9154 against 0.9130 (+0.26 %) with the contact dashpot sized by the bodies (the
  // default); 0.9036 (−1.0 %) sized by the tets; without contact and element damping 0.9190
  // (+0.7 %: the heel bounces a little).
  CHECK(std::abs(ratio - housner) < 0.01 * housner);
  CHECK(sim->energy().balance_error() < 0.01);
}
