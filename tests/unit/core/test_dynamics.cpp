// The central-difference update with Cundall's local damping: the closed-form decay of a linear
// oscillator, an exact energy balance, and no effect on prescribed components or nodes at rest;
// the split-phase internal forces of N ranks against the one-pass gather.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/dynamics.hpp"
#include "core/energy.hpp"
#include "core/model_builder.hpp"
#include "core/tet_kernels.hpp"
#include "one_body_scene.hpp"

using namespace fdem;

namespace {

// One free node of mass m on a spring k along x, released from x = 0 at speed v0.
NodeArrays one_node(double m, double v0) {
  NodeArrays nodes;
  nodes.resize(1);
  nodes.n_owned = 1;
  nodes.mass[0] = m;
  nodes.v[0] = v0;
  return nodes;
}

}  // namespace

TEST_CASE("local damping: a linear oscillator's turning points shrink by √((1−α)/(1+α))",
          "[dynamics][quasi_static]") {
  // With f_d = −α|f|sign(v) the spring is (1+α)k while the node moves away from rest and (1−α)k
  // while it comes back, so each half cycle keeps (1−α)/(1+α) of the energy: the amplitude of
  // successive turning points falls by r = √((1−α)/(1+α)) whatever m and k.
  const double m = 2.0, k = 50.0, alpha = 0.3, v0 = 1.5;
  const double omega = std::sqrt(k / m), dt = 1e-4 / omega;
  const double ratio = std::sqrt((1 - alpha) / (1 + alpha));
  NodeArrays nodes = one_node(m, v0);
  WorkAccumulator damping;
  double dissipated = 0.0, worst_balance = 0.0;
  const double e0 = 0.5 * m * v0 * v0;
  std::vector<double> turning;
  double previous_v = v0;
  for (int s = 0; s < 400000 && turning.size() < 6; ++s) {
    const double x = nodes.x[0];
    nodes.f.assign(3, 0.0);
    nodes.f[0] = -k * x;
    const IntegrationSummary step =
        integrate_central_difference(dt, nodes, StepDamping{true, alpha});
    // Balance at t_n: ½m·v⁻·v⁺ + ½kx² + dissipated = E0 (spring work by the trapezoid is exact).
    dissipated = -damping.add(step.damping_work_before, step.damping_work_after);
    if (s > 0)
      worst_balance = std::max(
          worst_balance, std::abs(step.kinetic_energy + 0.5 * k * x * x + dissipated - e0) / e0);
    if ((previous_v > 0) != (nodes.v[0] > 0)) turning.push_back(std::abs(nodes.x[0]));
    previous_v = nodes.v[0];
  }
  REQUIRE(turning.size() == 6);
  // The first turning point: ½m·v0² = ½(1+α)k·A².
  CHECK(turning[0] == Approx(v0 * std::sqrt(m / ((1 + alpha) * k))).epsilon(1e-3));
  for (std::size_t i = 1; i < turning.size(); ++i) {
    INFO("turning point " << i << ": " << turning[i] << " m after " << turning[i - 1]);
    CHECK(turning[i] / turning[i - 1] == Approx(ratio).epsilon(1e-3));
  }
  CHECK(worst_balance < 1e-12);
  CHECK(dissipated > 0.9 * e0);  // six half cycles keep r^12 = 2 % of it
}

TEST_CASE("local damping: nothing on prescribed components or nodes at rest, α = 0 is plain",
          "[dynamics][quasi_static]") {
  NodeArrays damped = one_node(1.0, 0.0);
  damped.v[1] = 0.5;
  damped.v[2] = -0.25;
  damped.constrained[0] = 4;  // z prescribed
  damped.prescribed_velocity[2] = -0.25;
  NodeArrays plain = damped;
  for (NodeArrays* nodes : {&damped, &plain}) nodes->f = {3.0, -2.0, 7.0};
  const IntegrationSummary d = integrate_central_difference(1e-3, damped, StepDamping{true, 0.8});
  const IntegrationSummary p = integrate_central_difference(1e-3, plain, StepDamping{true, 0.0});
  CHECK(damped.v[0] == plain.v[0]);  // at rest: no damping, the force accelerates it fully
  CHECK(damped.v[2] == -0.25);       // prescribed
  // Moving in +y against f_y = −2: the damping adds 0.8·2 N against the motion.
  CHECK(damped.v[1] == Approx(0.5 + 1e-3 * (-2.0 - 1.6)).epsilon(1e-14));
  CHECK(plain.v[1] == Approx(0.5 + 1e-3 * -2.0).epsilon(1e-14));
  CHECK(d.damping_work_before == Approx(0.5 * 1e-3 * -1.6 * 0.5));
  CHECK(p.damping_work_before == 0.0);
  CHECK(p.damping_work_after == 0.0);
}

namespace {

// A block of n³ cubes of 0.1 m, six tets each (Kuhn split), rock.
Model cube_block(int n) {
  const Scene scene = test::one_rock_body("block", 0.05);
  BodyMesh mesh;
  mesh.source = "test";
  const auto node = [&](int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        for (double c : {0.1 * i, 0.1 * j, 0.1 * k}) mesh.coords.push_back(c);
  const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                          {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& tet : kuhn) {
          LocalIndex v[4];
          for (int c = 0; c < 4; ++c)
            v[c] = node(i + (tet[c] & 1), j + ((tet[c] >> 1) & 1), k + ((tet[c] >> 2) & 1));
          const auto at = [&](int c) {
            return Vec3(mesh.coords[3 * v[c]], mesh.coords[3 * v[c] + 1],
                        mesh.coords[3 * v[c] + 2]);
          };
          if ((at(1) - at(0)).cross(at(2) - at(0)).dot(at(3) - at(0)) < 0.0) std::swap(v[2], v[3]);
          mesh.tets.insert(mesh.tets.end(), v, v + 4);
        }
  return build_model(scene, {mesh});
}

}  // namespace

TEST_CASE("split-phase internal forces equal the unsplit gather bit for bit", "[dynamics]") {
  Model model = cube_block(4);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> jitter(-2e-3, 2e-3);  // m: a deformed, moving block
  for (double& x : model.nodes.x) x += jitter(random);
  for (double& v : model.nodes.v) v = 1e2 * jitter(random);
  // The last 20 nodes play ghosts: the tets that use them are computed after the halo call.
  model.nodes.n_owned = model.nodes.size() - 20;
  const InternalForceSummary whole = compute_internal_forces(model);
  const std::vector<double> expected = model.nodes.f;

  InternalForceSplit split;
  build_internal_force_split(model, split);
  REQUIRE(!split.early.empty());
  REQUIRE(!split.late.empty());
  int halo_calls = 0;
  std::fill(model.nodes.f.begin(), model.nodes.f.end(), 1.0);  // stale values must not survive
  const InternalForceSummary parts = compute_internal_forces(model, split, [&] { ++halo_calls; });
  CHECK(halo_calls == 1);
  const std::size_t owned = 3 * static_cast<std::size_t>(model.nodes.n_owned);
  CHECK(std::memcmp(expected.data(), model.nodes.f.data(), owned * sizeof(double)) == 0);
  CHECK(parts.strain_energy == whole.strain_energy);
  CHECK(parts.damping_power == whole.damping_power);
  CHECK(parts.min_jacobian == whole.min_jacobian);
}

TEST_CASE(
    "the element loop's four-tet batches give every node the one-tet kernel's sums bit for bit",
    "[dynamics][lanes]") {
  Model model = cube_block(3);  // 162 tets: batches of four and a remainder of two
  MaterialProperties svk = model.materials[0];
  svk.model = ElasticModel::st_venant_kirchhoff;
  svk.lame.mu *= 1.5;
  model.materials.push_back(svk);
  MaterialProperties softer = model.materials[0];
  softer.lame.mu *= 0.7;
  model.materials.push_back(softer);
  // Runs of each law, some batches mixed (one tet at a time), neo-Hookean lanes of two stiffnesses,
  // viscosity on some tets only.
  for (LocalIndex t = 0; t < model.tets.size(); ++t) {
    model.tets.material[t] = (t / 6) % 3 == 2 ? 1 : t % 2 == 0 ? 0 : 2;
    model.tets.viscosity[t] = t % 5 == 0 ? 0.0 : model.tets.viscosity[t];
  }
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> jitter(-2e-3, 2e-3);
  for (double& x : model.nodes.x) x += jitter(random);
  for (double& v : model.nodes.v) v = 1e2 * jitter(random);
  const InternalForceSummary batched = compute_internal_forces(model);

  std::vector<double> expected(model.nodes.f.size(), 0.0);
  double strain_energy = 0.0, damping_power = 0.0;
  for (const LocalIndex t : model.tet_force_order) {
    Vec3 x[4], v[4];
    for (int c = 0; c < 4; ++c) {
      x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
      v[c] = vec3_at(model.nodes.v.data(), model.tets.nodes[4 * t + c]);
    }
    const Mat3 dm_inv = Eigen::Map<const Mat3>(model.tets.dm_inv.data() + 9 * t);
    const MaterialProperties& m = model.materials[model.tets.material[t]];
    const double eta = model.tets.viscosity[t];
    const TetForce f =
        m.model == ElasticModel::neo_hookean
            ? tet_internal_force(x, v, dm_inv, model.tets.volume0[t], NeoHookean{m.lame}, eta)
            : tet_internal_force(x, v, dm_inv, model.tets.volume0[t], StVenantKirchhoff{m.lame},
                                 eta);
    for (int c = 0; c < 4; ++c) vec3_at(expected.data(), model.tets.nodes[4 * t + c]) += f.force[c];
    strain_energy += f.strain_energy;
    damping_power += f.damping_power;
  }
  CHECK(std::memcmp(expected.data(), model.nodes.f.data(), expected.size() * sizeof(double)) == 0);
  CHECK(batched.strain_energy == strain_energy);
  CHECK(batched.damping_power == damping_power);
  CHECK(damping_power > 0.0);
}

namespace {

// The central-difference update as one loop with a test per component (the form before the
// free, undamped node got a path of its own): the reference for the bits below.
IntegrationSummary integrate_per_component(double dt, NodeArrays& nodes, double local_damping) {
  IntegrationSummary out;
  double kinetic2 = 0.0, kinetic_half2 = 0.0, max_dx2 = 0.0, power_old = 0.0, power_new = 0.0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    const double m = nodes.mass[n];
    const std::uint8_t mask = nodes.constrained[n];
    double dx2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * static_cast<std::size_t>(n) + k;
      const double v_old = nodes.v[i];
      double v_new = v_old + dt * nodes.f[i] / m;
      if (local_damping > 0.0 && !(mask & (1u << k)) && v_old != 0.0) {
        const double f_damping = -local_damping * std::abs(nodes.f[i]) * (v_old > 0 ? 1.0 : -1.0);
        v_new += dt * f_damping / m;
        power_old += f_damping * v_old;
        power_new += f_damping * v_new;
      }
      if (mask & (1u << k)) {
        v_new = nodes.prescribed_velocity[i];
        const double reaction = m * (v_new - v_old) / dt - nodes.f[i];
        out.constraint_work_before += 0.5 * reaction * dt * v_old;
        out.constraint_work_after += 0.5 * reaction * dt * v_new;
      }
      kinetic2 += m * v_old * v_new;
      kinetic_half2 += m * v_new * v_new;
      out.momentum_before[k] += m * v_old;
      out.momentum_after[k] += m * v_new;
      nodes.v[i] = v_new;
      const double dx = dt * v_new;
      nodes.x[i] += dx;
      dx2 += dx * dx;
    }
    max_dx2 = std::max(max_dx2, dx2);
  }
  out.damping_work_before = 0.5 * dt * power_old;
  out.damping_work_after = 0.5 * dt * power_new;
  out.kinetic_energy = 0.5 * kinetic2;
  out.kinetic_energy_half_step = 0.5 * kinetic_half2;
  out.max_displacement_increment = std::sqrt(max_dx2);
  return out;
}

}  // namespace

TEST_CASE(
    "the integration's free-node paths give the per-component loop's state bit for bit and its "
    "sums to round-off",
    "[dynamics]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  NodeArrays nodes;
  nodes.resize(2000);
  nodes.n_owned = 1901;  // ghosts stay as they are; the last node is a remainder of one
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    nodes.mass[n] = 0.5 + unit(rng) * 0.4;
    nodes.constrained[n] = n % 7 == 0 ? static_cast<std::uint8_t>(n % 8) : 0;
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * static_cast<std::size_t>(n) + k;
      nodes.x[i] = unit(rng);
      nodes.v[i] = n % 11 == 0 ? 0.0 : unit(rng);
      nodes.f[i] = 100.0 * unit(rng);
      nodes.prescribed_velocity[i] = unit(rng);
    }
  }
  const auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  // The sums are taken in another order (vector lanes): equal to a few units of round-off.
  const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-13 * std::abs(b); };
  for (const double alpha : {0.0, 0.8}) {
    NodeArrays a = nodes, b = nodes;
    const IntegrationSummary s =
        integrate_central_difference(1e-4, a, StepDamping{alpha > 0.0, alpha});
    const IntegrationSummary r = integrate_per_component(1e-4, b, alpha);
    REQUIRE(std::memcmp(a.x.data(), b.x.data(), a.x.size() * sizeof(double)) == 0);
    REQUIRE(std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(double)) == 0);
    CHECK(close(s.kinetic_energy, r.kinetic_energy));
    CHECK(close(s.kinetic_energy_half_step, r.kinetic_energy_half_step));
    CHECK(same(s.constraint_work_before, r.constraint_work_before));
    CHECK(same(s.constraint_work_after, r.constraint_work_after));
    CHECK(same(s.damping_work_before, r.damping_work_before));
    CHECK(same(s.damping_work_after, r.damping_work_after));
    CHECK(same(s.max_displacement_increment, r.max_displacement_increment));
    for (int k = 0; k < 3; ++k) {
      CHECK(std::abs(s.momentum_before[k] - r.momentum_before[k]) <= 1e-12);
      CHECK(std::abs(s.momentum_after[k] - r.momentum_after[k]) <= 1e-12);
    }
    CHECK(r.constraint_work_before != 0.0);
    if (alpha > 0.0) CHECK(r.damping_work_before != 0.0);
  }
}

TEST_CASE("the integration names the node that moved furthest in the step, a NaN one first",
          "[dynamics]") {
  NodeArrays nodes;
  nodes.resize(11);
  nodes.n_owned = 10;
  for (LocalIndex n = 0; n < nodes.size(); ++n) nodes.mass[n] = 1.0;
  {
    NodeArrays still = nodes;
    const IntegrationSummary s = integrate_central_difference(1e-3, still);
    CHECK(s.fastest_node == -1);
    CHECK(s.max_displacement_increment == 0.0);
  }
  for (const LocalIndex fast : {0, 5, 9}) {  // in a four-node vector, and the remainder
    NodeArrays moving = nodes;
    for (LocalIndex n = 0; n < moving.size(); ++n) moving.v[3 * n + 1] = 0.1 * (n % 3);
    moving.v[3 * fast + 2] = 7.0;
    moving.v[3 * 10] = 100.0;  // a ghost: not integrated
    const IntegrationSummary s = integrate_central_difference(1e-3, moving);
    CHECK(s.fastest_node == fast);
    CHECK(s.max_displacement_increment == Approx(1e-3 * std::hypot(7.0, 0.1 * (fast % 3))));
    moving.v[3 * 3] = std::numeric_limits<double>::quiet_NaN();
    moving.v[3 * 6] = std::numeric_limits<double>::quiet_NaN();
    const IntegrationSummary bad = integrate_central_difference(1e-3, moving);
    CHECK(bad.fastest_node == 3);
    CHECK(bad.max_displacement_increment == std::numeric_limits<double>::infinity());
    CHECK(!bad.finite);
  }
}
