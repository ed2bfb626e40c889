// 6-node joint kernel: objectivity, balance of forces and moments, exact gradient, energy
// consistency along a path, full separation in pure and mixed modes.
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "fracture/joint_kernels.hpp"
#include "fracture_test_support.hpp"

using namespace fdem;
using fdem::test::rock_parameters;

namespace {

// A skewed triangle: a0, a1, a2 with (a1−a0)×(a2−a0) ∥ +z (A below, B above).
struct Face {
  Vec3 a[3] = {Vec3(0.10, 0.20, 0.05), Vec3(0.21, 0.23, 0.05), Vec3(0.13, 0.29, 0.05)};
  double area() const { return 0.5 * (a[1] - a[0]).cross(a[2] - a[0]).norm(); }
};

// Joint positions: b_i = a_i + gap_i, then the whole joint moved rigidly by (Q, shift).
void place(const Face& f, const Vec3 (&gap)[3], const Mat3& Q, const Vec3& shift, Vec3 (&x)[6]) {
  for (int i = 0; i < 3; ++i) {
    x[i] = Q * f.a[i] + shift;
    x[3 + i] = Q * (f.a[i] + gap[i]) + shift;
  }
}

Mat3 rotation(double angle, Vec3 axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

double max_norm(const JointForce& r) {
  double m = 0.0;
  for (const auto& f : r.force) m = std::max(m, f.norm());
  return m;
}

}  // namespace

TEST_CASE("rigid rotation (to 180°) and translation: no opening, no force, no damage",
          "[fracture][joint]") {
  const CohesiveLaw law(rock_parameters());
  const Face face;
  const Vec3 zero[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  const double force_scale = 5.0e6 * face.area();  // f_t·A (N)
  JointHistory h;
  double worst = 0.0;
  for (int k = 0; k <= 180; ++k) {  // one step per degree, history carried along
    const double angle = M_PI * k / 180.0;
    Vec3 x[6];
    place(face, zero, rotation(angle, Vec3(1, 2, 3)), Vec3(10.0, -5.0, 3.0) * k / 180.0, x);
    const JointForce r = joint_force(x, face.area(), law, h);
    worst = std::max(worst, max_norm(r) / force_scale);
    REQUIRE(!r.degenerate);
    CHECK(r.stored_energy == 0.0);
    CHECK(r.fracture_energy == 0.0);
  }
  std::printf("  rigid motion: largest |f| / (f_t·A) = %.3e\n", worst);
  CHECK(worst <= 1e-12);
  CHECK(h.damage() == 0.0);
  CHECK(!h.broken);

  // An opened, partly damaged joint: the same local state in any rigid placement, forces rotate
  // with it (f(Qx + c) = Q f(x)), energies are unchanged.
  const double dc = law.critical_opening();
  const Vec3 gap[3] = {Vec3(0.2 * dc, 0.1 * dc, 0.4 * dc), Vec3(-0.1 * dc, 0.3 * dc, 0.2 * dc),
                       Vec3(0.05 * dc, -0.2 * dc, -0.02 * dc)};
  JointHistory loaded;
  for (int k = 1; k <= 100; ++k) {
    Vec3 x[6];
    const Vec3 g[3] = {gap[0] * k / 100.0, gap[1] * k / 100.0, gap[2] * k / 100.0};
    place(face, g, Mat3::Identity(), Vec3::Zero(), x);
    joint_force(x, face.area(), law, loaded);
  }
  REQUIRE(loaded.damage() > 0.0);
  Vec3 x0[6];
  place(face, gap, Mat3::Identity(), Vec3::Zero(), x0);
  JointHistory reference_history = loaded;
  const JointForce reference = joint_force(x0, face.area(), law, reference_history);
  double worst_rotated = 0.0;
  for (double degrees : {30.0, 90.0, 179.9, 180.0}) {
    const Mat3 Q = rotation(degrees * M_PI / 180.0, Vec3(-1, 0.5, 2));
    Vec3 x[6];
    place(face, gap, Q, Vec3(0.3, 0.1, -0.2), x);
    JointHistory h2 = loaded;
    const JointForce r = joint_force(x, face.area(), law, h2);
    for (int i = 0; i < 6; ++i)
      worst_rotated = std::max(worst_rotated,
                               (r.force[i] - Q * reference.force[i]).norm() / max_norm(reference));
    CHECK(r.stored_energy == Approx(reference.stored_energy).epsilon(1e-9));
    CHECK(h2.damage() == Approx(reference_history.damage()).epsilon(1e-9));
  }
  std::printf("  opened joint moved rigidly: largest |f(Qx) − Q f(x)| / max|f| = %.3e\n",
              worst_rotated);
  CHECK(worst_rotated <= 1e-8);  // round-off of gaps ~1e-5 m measured from coordinates ~0.3 m
}

TEST_CASE("forces and moments balance for arbitrary deformations, forces = −∂ψ/∂x",
          "[fracture][joint]") {
  const CohesiveLaw law(rock_parameters());
  const Face face;
  const double dc = law.critical_opening();
  std::srand(7);
  auto random = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
  double worst_force = 0.0, worst_moment = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 x[6];
    const Mat3 Q = rotation(3.0 * random(), Vec3(random(), random(), random() + 1.5));
    for (int i = 0; i < 3; ++i) {
      // Gaps up to 2·δc in any direction, plus distortion of the faces themselves.
      const Vec3 gap(2 * dc * random(), 2 * dc * random(), 2 * dc * random());
      const Vec3 distortion(0.01 * random(), 0.01 * random(), 0.01 * random());
      x[i] = Q * (face.a[i] + distortion);
      x[3 + i] = Q * (face.a[i] + distortion + gap);
    }
    JointHistory h;
    const JointForce r = joint_force(x, face.area(), law, h);
    Vec3 sum = Vec3::Zero(), moment = Vec3::Zero();
    double scale_f = 0.0, scale_m = 0.0;
    for (int i = 0; i < 6; ++i) {
      sum += r.force[i];
      moment += x[i].cross(r.force[i]);
      scale_f += r.force[i].norm();
      scale_m += x[i].norm() * r.force[i].norm();
    }
    if (scale_f == 0.0) continue;
    worst_force = std::max(worst_force, sum.norm() / scale_f);
    worst_moment = std::max(worst_moment, moment.norm() / scale_m);
  }
  std::printf("  balance over 200 random states: |Σf|/Σ|f| = %.3e, |Σx×f|/Σ|x||f| = %.3e\n",
              worst_force, worst_moment);
  CHECK(worst_force <= 1e-14);
  CHECK(worst_moment <= 1e-12);

  // Central differences of the stored energy (elastic, undamaged states, with a frozen copy of the
  // history at every evaluation) reproduce the forces, frame-rotation terms included (they vanish
  // for p_t = p_n, hence a softer tangential penalty here).
  auto soft = rock_parameters();
  soft.tangential_penalty = 0.5 * soft.normal_penalty;
  const CohesiveLaw anisotropic(soft);
  const double dt = law.peak_opening();
  const Vec3 gap[3] = {Vec3(0.5 * dt, -0.3 * dt, 0.8 * dt), Vec3(0.2 * dt, 0.6 * dt, -0.9 * dt),
                       Vec3(-0.7 * dt, 0.1 * dt, 0.4 * dt)};
  Vec3 x[6];
  place(face, gap, rotation(0.7, Vec3(1, 1, 0)), Vec3(0.1, 0.2, 0.3), x);
  JointHistory fresh;
  const JointForce r = joint_force(x, face.area(), anisotropic, fresh);
  REQUIRE(fresh.damage() == 0.0);
  double worst_fd = 0.0;
  const double step = 1e-4 * dt;
  for (int node = 0; node < 6; ++node) {
    for (int k = 0; k < 3; ++k) {
      Vec3 xp[6], xm[6];
      for (int j = 0; j < 6; ++j) xp[j] = xm[j] = x[j];
      xp[node][k] += step;
      xm[node][k] -= step;
      JointHistory hp, hm;
      const double fd = -(joint_force(xp, face.area(), anisotropic, hp).stored_energy -
                          joint_force(xm, face.area(), anisotropic, hm).stored_energy) /
                        (2 * step);
      worst_fd = std::max(worst_fd, std::abs(fd - r.force[node][k]) / max_norm(r));
    }
  }
  std::printf("  gradient check: largest |f + ∂ψ/∂x| / max|f| = %.3e\n", worst_fd);
  CHECK(worst_fd <= 1e-6);
}

TEST_CASE(
    "damaged, slipped joint: forces = −∂ψ/∂x in elastic unloading, intact fast path "
    "agrees with the general path",
    "[fracture][joint]") {
  const CohesiveLaw law(rock_parameters());
  const Face face;
  const double dc = law.critical_opening(), sc = law.critical_slip();
  const Mat3 Q = rotation(2.2, Vec3(0.2, 1, -0.4));
  const Vec3 shift(-0.4, 0.7, 0.1);
  const Vec3 loaded[3] = {Vec3(0.3 * sc, 0.05 * sc, 0.3 * dc), Vec3(-0.2 * sc, 0.1 * sc, 0.1 * dc),
                          Vec3(0.1 * sc, -0.15 * sc, -0.01 * dc)};
  JointHistory h;
  for (int k = 1; k <= 400; ++k) {
    Vec3 g[3], x[6];
    for (int i = 0; i < 3; ++i) g[i] = loaded[i] * (k / 400.0);
    place(face, g, Q, shift, x);
    joint_force(x, face.area(), law, h);
  }
  REQUIRE(h.point[0].damage > 0.1);
  REQUIRE(h.point[0].slip_length > 0.0);
  // Back off a little: normal gaps shrink (secant branch), slips retreat inside the yield surface.
  Vec3 unloaded[3];
  for (int i = 0; i < 3; ++i) {
    const Vec3 slip(loaded[i][0], loaded[i][1], 0.0);
    unloaded[i] = loaded[i] - 0.2 * law.peak_opening() * slip.normalized();
    unloaded[i][2] *= 0.7;
  }
  Vec3 x[6];
  place(face, unloaded, Q, shift, x);
  JointHistory base = h;
  const JointForce r = joint_force(x, face.area(), law, base);
  REQUIRE(r.fracture_energy == 0.0);
  REQUIRE(r.friction_energy == 0.0);
  double worst_fd = 0.0;
  const double step = 1e-5 * law.peak_opening();
  for (int node = 0; node < 6; ++node) {
    for (int k = 0; k < 3; ++k) {
      Vec3 xp[6], xm[6];
      for (int j = 0; j < 6; ++j) xp[j] = xm[j] = x[j];
      xp[node][k] += step;
      xm[node][k] -= step;
      JointHistory hp = h, hm = h;
      const JointForce rp = joint_force(xp, face.area(), law, hp);
      const JointForce rm = joint_force(xm, face.area(), law, hm);
      REQUIRE(rp.fracture_energy + rp.friction_energy + rm.fracture_energy + rm.friction_energy ==
              0.0);
      const double fd = -(rp.stored_energy - rm.stored_energy) / (2 * step);
      worst_fd = std::max(worst_fd, std::abs(fd - r.force[node][k]) / max_norm(r));
    }
  }
  std::printf("  gradient check, damaged joint: largest |f + ∂ψ/∂x| / max|f| = %.3e\n", worst_fd);
  CHECK(worst_fd <= 1e-6);  // central-difference error here is ~1e-7

  // The intact fast path and the general path (forced by a history that is damaged by 1e-300)
  // give the same forces and energy (p_t ≠ p_n so that the frame terms matter).
  auto soft = rock_parameters();
  soft.tangential_penalty = 0.5 * soft.normal_penalty;
  const CohesiveLaw anisotropic(soft);
  const double dt = law.peak_opening();
  const Vec3 small[3] = {Vec3(0.5 * dt, -0.3 * dt, 0.8 * dt), Vec3(0.2 * dt, 0.6 * dt, -0.9 * dt),
                         Vec3(-0.7 * dt, 0.1 * dt, 0.4 * dt)};
  place(face, small, Q, shift, x);
  JointHistory intact, marked;
  marked.point[1].max_opening_ratio = 1e-300;
  const JointForce fast = joint_force(x, face.area(), anisotropic, intact);
  const JointForce general = joint_force(x, face.area(), anisotropic, marked);
  double worst_path = 0.0;
  for (int i = 0; i < 6; ++i)
    worst_path = std::max(worst_path, (fast.force[i] - general.force[i]).norm() / max_norm(fast));
  std::printf("  fast vs general path: largest force difference / max|f| = %.3e\n", worst_path);
  CHECK(worst_path <= 1e-9);
  CHECK(fast.stored_energy == Approx(general.stored_energy).epsilon(1e-9));
}

TEST_CASE("energy: stored change + dissipated = work of the nodal forces along a path",
          "[fracture][joint]") {
  const CohesiveLaw law(rock_parameters());
  const Face face;
  const double dc = law.critical_opening();
  const double sc = law.critical_slip();
  // Each gap has its own smooth history: point 0 first closes (compression, friction) then opens,
  // the others open and slide; the joint turns 90° and translates meanwhile.
  auto gaps = [&](double s, Vec3(&g)[3]) {
    g[0] = Vec3(1.0 * sc * s, 0.2 * sc * s * s, 1.5 * dc * s - 0.8 * dc * std::sin(M_PI * s));
    g[1] = Vec3(-0.3 * sc * s, 0.5 * sc * s, 1.2 * dc * s * s);
    g[2] = Vec3(0.8 * sc * std::sin(0.5 * M_PI * s), -0.1 * sc * s, 0.7 * dc * s);
  };
  for (int steps : {2000, 20000}) {
    JointHistory h;
    Vec3 x_old[6], g0[3];
    gaps(0.0, g0);
    place(face, g0, Mat3::Identity(), Vec3::Zero(), x_old);
    JointForce r_old = joint_force(x_old, face.area(), law, h);
    const double stored_start = r_old.stored_energy;
    double work = 0.0, dissipated = 0.0, fracture = 0.0, friction = 0.0, stored_end = 0.0;
    for (int k = 1; k <= steps; ++k) {
      const double s = static_cast<double>(k) / steps;
      Vec3 g[3], x[6];
      gaps(s, g);
      place(face, g, rotation(0.5 * M_PI * s, Vec3(0.3, -1, 0.4)), Vec3(0.5, 0.0, -0.2) * s, x);
      const JointForce r = joint_force(x, face.area(), law, h);
      for (int i = 0; i < 6; ++i) work -= 0.5 * (r.force[i] + r_old.force[i]).dot(x[i] - x_old[i]);
      fracture += r.fracture_energy;
      friction += r.friction_energy;
      stored_end = r.stored_energy;
      r_old = r;
      for (int i = 0; i < 6; ++i) x_old[i] = x[i];
    }
    dissipated = fracture + friction;
    const double error = std::abs(stored_end - stored_start + dissipated - work) / work;
    std::printf(
        "  energy path, %5d steps: work %.9e J, fracture %.6e J, friction %.6e J, "
        "stored %.3e J, relative error %.2e\n",
        steps, work, fracture, friction, stored_end, error);
    CHECK(fracture > 0.0);
    CHECK(friction > 0.0);
    CHECK(error <= (steps == 2000 ? 1e-4 : 1e-6));
  }
}

TEST_CASE("full separation of a joint: G·A dissipated, broken flag, failure mode",
          "[fracture][joint]") {
  const auto p = rock_parameters();
  const CohesiveLaw law(p);
  const Face face;
  const double A = face.area();
  auto separate = [&](const Vec3& direction, double reach, int steps, JointHistory& h) {
    double fracture = 0.0, peak = 0.0;
    int broken_at = -1;
    for (int k = 0; k <= steps; ++k) {
      const Vec3 g = direction * (reach * k / steps);
      const Vec3 gap[3] = {g, g, g};
      Vec3 x[6];
      place(face, gap, rotation(1.0, Vec3(0, 1, 1)), Vec3(1, 2, 3), x);
      const JointForce r = joint_force(x, A, law, h);
      fracture += r.fracture_energy;
      const Vec3 on_b = r.force[3] + r.force[4] + r.force[5];
      peak = std::max(peak, on_b.norm() / A);
      if (r.newly_broken) broken_at = k;
    }
    return std::make_tuple(fracture / A, peak, broken_at);
  };
  {
    JointHistory h;
    const auto [g, peak, broken_at] =
        separate(Vec3(0, 0, 1), 1.1 * law.critical_opening(), 20000, h);
    std::printf("  joint tension: %.6f J/m^2 (G_I 50), peak %.6f MPa, mode %s\n", g, peak / 1e6,
                failure_mode_name(h.mode));
    CHECK(g == Approx(p.energy_I).epsilon(0.005));
    CHECK(peak == Approx(p.tensile_strength).epsilon(0.02));
    CHECK(h.broken);
    CHECK(h.mode == FailureMode::tension);
    CHECK(broken_at > 0);
    CHECK(h.damage() == 1.0);
  }
  {
    JointHistory h;
    const auto [g, peak, broken_at] = separate(Vec3(1, 0, 0), 1.1 * law.critical_slip(), 20000, h);
    std::printf("  joint shear: %.6f J/m^2 (G_II 250), peak %.6f MPa, mode %s\n", g, peak / 1e6,
                failure_mode_name(h.mode));
    CHECK(g == Approx(p.energy_II).epsilon(0.005));
    CHECK(peak == Approx(p.cohesion).epsilon(0.02));
    CHECK(h.broken);
    CHECK(h.mode == FailureMode::shear);
  }
  {
    JointHistory h;
    const Vec3 dir = Vec3(law.critical_slip(), 0, 0.3 * law.critical_opening());
    separate(dir.normalized(), dir.norm() * 1.2, 20000, h);
    CHECK(h.broken);
    CHECK(h.mode == FailureMode::mixed_shear);
    std::printf("  mixed separation: mode %s\n", failure_mode_name(h.mode));
  }
  {  // A broken joint exerts nothing, whatever happens to its faces afterwards.
    JointHistory h;
    separate(Vec3(0, 0, 1), 1.1 * law.critical_opening(), 2000, h);
    const Vec3 gap[3] = {Vec3(0, 0, -1e-5), Vec3(0, 0, -1e-5), Vec3(0, 0, 2e-5)};
    Vec3 x[6];
    place(face, gap, Mat3::Identity(), Vec3::Zero(), x);
    const JointForce r = joint_force(x, A, law, h);
    CHECK(max_norm(r) == 0.0);
    CHECK(!r.newly_broken);
  }
}

TEST_CASE("cost of an intact joint below strength", "[fracture][joint][.perf]") {
  const CohesiveLaw law(rock_parameters());
  const Face face;
  const double dt = law.peak_opening();
  const Vec3 gap[3] = {Vec3(0.1 * dt, 0, 0.3 * dt), Vec3(0, 0.2 * dt, 0.1 * dt),
                       Vec3(0.05 * dt, 0, -0.2 * dt)};
  Vec3 x[6];
  place(face, gap, Mat3::Identity(), Vec3::Zero(), x);
  JointHistory h;
  const int n = 2000000;
  double sink = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < n; ++k) {
    x[3][2] += 1e-20;
    sink += joint_force(x, face.area(), law, h).force[0][2];
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("  intact joint: %.1f ns per evaluation (%g)\n", 1e9 * seconds / n, sink);
  CHECK(seconds > 0.0);
}
