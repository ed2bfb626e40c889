// Cohesive law of one integration point: softening curve, pure modes, friction, unloading,
// mixed mode, parameter validation.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.hpp"
#include "fracture/cohesive_law.hpp"
#include "fracture_test_support.hpp"

using namespace fdem;
using fdem::test::drive_point;
using fdem::test::rock_parameters;

TEST_CASE("softening curve z(D): end values, monotone, integral 0.3863", "[fracture][softening]") {
  const SofteningCurve curve;  // (0.63, 1.8, 6.0)
  CHECK(curve.z(0.0) == Approx(1.0).margin(1e-14));
  CHECK(curve.z(1.0) == 0.0);
  CHECK(curve.z(1.0 - 1e-9) == Approx(0.0).margin(1e-8));
  double previous = curve.z(0.0);
  for (int i = 1; i <= 10000; ++i) {
    const double value = curve.z(i / 10000.0);
    REQUIRE(value <= previous + 1e-15);
    previous = value;
  }
  // docs/references.md item 10: ∫₀¹ z dD = 0.3863 (4 digits); cross-check with an independent
  // Simpson rule.
  CHECK(std::round(curve.integral() * 1e4) / 1e4 == Approx(0.3863).margin(1e-12));
  const double simpson =
      fdem::test::simpson([](double D) { return fdem::test::z_reference(D); }, 0.0, 1.0, 200000);
  CHECK(curve.integral() == Approx(simpson).epsilon(1e-10));
  // The analytic slope agrees with a central difference; z'(0) ≈ 0 (smooth peak).
  for (double D : {0.1, 0.37, 0.8}) {
    const double fd = (curve.z(D + 1e-6) - curve.z(D - 1e-6)) / 2e-6;
    CHECK(curve.dz(D) == Approx(fd).epsilon(1e-6));
  }
  CHECK(std::abs(curve.dz(0.0)) < 1e-3);
  CHECK(curve.max_slope() == Approx(2.040).epsilon(1e-3));
}

TEST_CASE("pure mode I: peak f_t, dissipation G_I", "[fracture][law]") {
  const CohesiveLaw law(rock_parameters());
  const double dc = law.critical_opening();
  CohesivePointState st;
  const auto t = drive_point(
      law, st, [&](double s) { return Vec3(0, 0, 1.2 * dc * s); }, 20000);
  INFO("dissipated " << t.fracture << " J/m^2, peak " << t.max_normal << " Pa");
  std::printf("  mode I: dissipated %.6f J/m^2 (G_I = 50), peak %.6f MPa (f_t = 5)\n", t.fracture,
              t.max_normal / 1e6);
  CHECK(t.max_normal == Approx(5.0e6).epsilon(0.02));
  CHECK(t.fracture == Approx(50.0).epsilon(0.005));
  CHECK(t.work == Approx(50.0).epsilon(0.005));
  CHECK(t.friction == 0.0);
  CHECK(t.stored_end == 0.0);
  CHECK(st.damage == 1.0);
  // On the softening branch σ = z(D)·f_t with D = (δ − δt)/(δc − δt) (eq. 19–21).
  CohesivePointState st2;
  const double dt = law.peak_opening();
  for (double D : {0.1, 0.5, 0.9}) {
    const double dn = dt + D * (dc - dt);
    const auto r = law.update(Vec3(0, 0, dn), st2);
    CHECK(r.traction[2] == Approx(law.softening().z(D) * 5.0e6).epsilon(1e-12));
  }
}

TEST_CASE("pure mode II: peak c, dissipation G_II", "[fracture][law]") {
  const CohesiveLaw law(rock_parameters());
  CohesivePointState st;
  const double reach = 1.3 * law.critical_slip();
  const auto t = drive_point(
      law, st, [&](double s) { return Vec3(reach * s, 0, 0); }, 20000);
  INFO("dissipated " << t.fracture << " J/m^2, peak " << t.max_shear << " Pa");
  std::printf("  mode II: dissipated %.6f J/m^2 (G_II = 250), peak %.6f MPa (c = 10)\n", t.fracture,
              t.max_shear / 1e6);
  CHECK(t.max_shear == Approx(10.0e6).epsilon(0.02));
  CHECK(t.fracture == Approx(250.0).epsilon(0.005));
  CHECK(t.work == Approx(250.0).epsilon(0.005));
  CHECK(t.friction == 0.0);
  CHECK(st.damage == 1.0);
}

TEST_CASE("shear under compression: peak c + σc·tanφ, friction does not soften",
          "[fracture][law]") {
  const CohesiveLaw law(rock_parameters());
  const double sigma_c = 4.0e6;
  const double dn = -sigma_c / law.normal_stiffness();
  const double tan_phi = std::tan(30.0 * M_PI / 180.0);
  CohesivePointState st;
  const double reach = 1.5 * law.critical_slip();
  drive_point(
      law, st, [&](double s) { return Vec3(0, 0, dn * s); }, 100);
  const double stored_start = 0.5 * sigma_c * (-dn);
  const auto t = drive_point(
      law, st, [&](double s) { return Vec3(reach * s, 0, dn); }, 20000);
  const double peak = 10.0e6 + sigma_c * tan_phi;
  INFO("peak " << t.max_shear << " expected " << peak << "; fracture " << t.fracture << " friction "
               << t.friction);
  std::printf(
      "  shear at σc = 4 MPa: peak %.6f MPa (c + σc·tanφ = %.6f), fracture %.6f J/m^2, "
      "friction %.4f J/m^2\n",
      t.max_shear / 1e6, peak / 1e6, t.fracture, t.friction);
  CHECK(t.max_shear == Approx(peak).epsilon(0.02));
  const double slip_on_path = st.slip_length;
  // After full degradation the joint still slides at the friction stress σc·tanφ.
  const auto r = law.update(Vec3(reach * 1.01, 0, dn), st);
  CHECK(std::hypot(r.traction[0], r.traction[1]) == Approx(sigma_c * tan_phi).epsilon(1e-9));
  CHECK(r.traction[2] == Approx(-sigma_c).epsilon(1e-12));
  // Cohesive part dissipates exactly G_II; friction = σc·tanφ·(total plastic slip).
  CHECK(t.fracture == Approx(250.0).epsilon(0.005));
  CHECK(t.friction == Approx(sigma_c * tan_phi * slip_on_path).epsilon(1e-6));
  CHECK(t.work == Approx(t.stored_end - stored_start + t.fracture + t.friction).epsilon(1e-6));
}

TEST_CASE("dry joint (c = 0, tanφ = 0.65): τ_peak = 0.65σn, no softening, no damage",
          "[fracture][law]") {
  auto p = rock_parameters();
  p.cohesion = 0.0;
  p.energy_II = 0.0;  // not needed without cohesion
  p.friction_angle_deg = std::atan(0.65) * 180.0 / M_PI;
  const CohesiveLaw law(p);
  for (double sigma_n : {0.25e6, 0.5e6, 1.0e6}) {
    CohesivePointState st;
    const double dn = -sigma_n / law.normal_stiffness();
    drive_point(
        law, st, [&](double s) { return Vec3(0, 0, dn * s); }, 10);
    const double slip = 1e-3;  // 1 mm: far beyond the elastic 0.65σn/k_t
    const auto t = drive_point(
        law, st, [&](double s) { return Vec3(slip * s, 0, dn); }, 2000);
    const double last = std::abs(law.update(Vec3(slip, 0, dn), st).traction[0]);
    INFO("σn = " << sigma_n << ": peak " << t.max_shear << ", final " << last);
    CHECK(t.max_shear == Approx(0.65 * sigma_n).epsilon(0.02));
    CHECK(last == Approx(0.65 * sigma_n).epsilon(1e-9));  // plateau: friction never softens
    CHECK(st.damage == 0.0);
    CHECK(t.fracture == 0.0);
    // Trapezoidal accounting misses ½·τ·Δκ at the step that crosses the yield point: 1e-3.
    CHECK(t.friction == Approx(0.65 * sigma_n * st.slip_length).epsilon(1e-3));
    std::printf("  dry joint σn = %.2f MPa: peak τ %.6f MPa (0.65σn = %.6f), after 1 mm %.6f MPa\n",
                sigma_n / 1e6, t.max_shear / 1e6, 0.65 * sigma_n / 1e6, last / 1e6);
  }
  // docs/references.md item 12: 200 × 200 mm face at 0.5 MPa → 13 kN.
  CHECK(0.65 * 0.5e6 * 0.2 * 0.2 == Approx(13.0e3).epsilon(1e-12));
}

TEST_CASE("unloading and reloading: secant in tension, elastic in shear, no healing",
          "[fracture][law]") {
  const CohesiveLaw law(rock_parameters());
  const double dt = law.peak_opening(), dc = law.critical_opening();
  const double k_n = law.normal_stiffness(), k_t = law.tangential_stiffness();

  SECTION("mode I: secant to the origin, full penalty in compression, envelope on reload") {
    CohesivePointState st;
    const double d1 = dt + 0.3 * (dc - dt);
    auto t = drive_point(
        law, st, [&](double s) { return Vec3(0, 0, d1 * s); }, 2000);
    const double D1 = st.damage;
    REQUIRE(D1 == Approx(0.3).epsilon(1e-12));
    const double secant = law.secant_factor(D1) * k_n;
    // Unload through zero into compression, then reload to d1.
    for (int k = 0; k <= 200; ++k) {
      const double dn = d1 - (d1 + dt) * k / 200.0;
      const auto r = law.update(Vec3(0, 0, dn), st);
      CHECK(st.damage == D1);
      if (dn > 0)
        CHECK(r.traction[2] == Approx(secant * dn).epsilon(1e-12));
      else
        CHECK(r.traction[2] == Approx(k_n * dn).epsilon(1e-12));  // closed crack: full penalty
      CHECK(r.fracture_energy == 0.0);
    }
    t = drive_point(
        law, st, [&](double s) { return Vec3(0, 0, -dt + (d1 + dt) * s); }, 200, t);
    CHECK(st.damage == D1);
    const auto back = law.update(Vec3(0, 0, d1), st);
    CHECK(back.traction[2] == Approx(law.softening().z(D1) * 5.0e6).epsilon(1e-12));
    // Continue past δc: the rest of G_I is dissipated, the whole cycle totals G_I.
    t = drive_point(
        law, st, [&](double s) { return Vec3(0, 0, d1 + (1.2 * dc - d1) * s); }, 20000, t);
    CHECK(t.fracture == Approx(50.0).epsilon(0.005));
  }

  SECTION("mode II: elastic unloading with slope k_t, reverse yield at z(D)·c, D never drops") {
    CohesivePointState st;
    const double s1 = 0.3 * law.critical_slip();
    drive_point(
        law, st, [&](double s) { return Vec3(s1 * s, 0, 0); }, 4000);
    const double D1 = st.damage;
    const double offset = st.plastic_slip[0];
    REQUIRE(D1 > 0.2);
    double previous_damage = D1;
    bool reverse_yield = false;
    for (int k = 1; k <= 4000; ++k) {
      const double s = s1 - 2.0 * s1 * k / 4000.0;
      const auto r = law.update(Vec3(s, 0, 0), st);
      CHECK(st.damage >= previous_damage);
      previous_damage = st.damage;
      if (st.plastic_slip[0] == offset) {
        CHECK(r.traction[0] == Approx(k_t * (s - offset)).epsilon(1e-12));
      } else if (!reverse_yield) {
        reverse_yield = true;
        CHECK(r.traction[0] == Approx(-10.0e6 * law.softening().z(st.damage)).epsilon(1e-3));
      }
    }
    CHECK(reverse_yield);
    CHECK(st.damage > D1);
  }
}

TEST_CASE("mixed mode along o = s (45° in normalised opening/slip space)", "[fracture][law]") {
  // Rule (docs/fracture-model.md): D = min(1, √(o_max² + (κ/s_c)²)), σ = S(D)·k_n·δn,
  // |τ| ≤ c·z(D) + σc·tanφ.  Path: both modes loaded elastically to their peaks together, then
  // δn = δt + u(δc − δt) and slip κ = u·s_c, u = 0…1/√2 (D = √2·u reaches 1).  Prediction:
  //   W = ½f_tδt + f_t(δc−δt)·∫₀^{1/√2} z(√2u)·(δt + u(δc−δt))/(δt + √2u(δc−δt)) du + G_II/√2,
  // with the normal part between G_I/2 and G_I and the total below G_I + G_II.
  const auto p = rock_parameters();
  const CohesiveLaw law(p);
  const double dt = law.peak_opening(), dc = law.critical_opening(), sc = law.critical_slip();
  const double dst = p.cohesion / law.tangential_stiffness();
  const double k_t = law.tangential_stiffness();
  const double root2 = std::sqrt(2.0);
  auto path = [&](double s) {
    if (s <= 0.1) {
      const double l = s / 0.1;
      return Vec3(l * dst, 0, l * dt);
    }
    const double u = (s - 0.1) / 0.9 / root2;
    const double D = std::min(1.0, root2 * u);
    return Vec3(u * sc + p.cohesion * fdem::test::z_reference(D) / k_t, 0, dt + u * (dc - dt));
  };
  CohesivePointState st;
  const auto t = drive_point(law, st, path, 40000);
  const double range = dc - dt;
  const double J = fdem::test::simpson(
      [&](double u) {
        return fdem::test::z_reference(root2 * u) * (dt + u * range) / (dt + root2 * u * range);
      },
      0.0, 1.0 / root2, 20000);
  const double normal_part = 0.5 * p.tensile_strength * dt + p.tensile_strength * range * J;
  const double predicted = normal_part + p.energy_II / root2;
  INFO("dissipated " << t.fracture << " J/m^2, predicted " << predicted << " (normal part "
                     << normal_part << ", shear part " << p.energy_II / root2 << ")");
  std::printf("  mixed o = s: dissipated %.6f J/m^2, predicted %.6f (normal %.4f, shear %.4f)\n",
              t.fracture, predicted, normal_part, p.energy_II / root2);
  CHECK(t.fracture == Approx(predicted).epsilon(0.005));
  CHECK(normal_part > 0.5 * p.energy_I);
  CHECK(normal_part < p.energy_I);
  CHECK(t.fracture < p.energy_I + p.energy_II);
  CHECK(st.damage == 1.0);
  // The return mapping recovers the prescribed plastic slip κ = u·s_c (u = 1/√2 at the end).
  CHECK(st.slip_length == Approx(sc / root2).epsilon(1e-9));
}

TEST_CASE("impossible parameters are rejected with a helpful message", "[fracture][law]") {
  auto message = [](const CohesiveParameters& p) -> std::string {
    try {
      CohesiveLaw law(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  SECTION("G_I below the pre-peak penalty energy") {
    auto p = rock_parameters();
    p.energy_I = 4.0;  // ½·f_t²·h/p_n = 4.17 J/m²
    const std::string m = message(p);
    INFO(m);
    CHECK(m.find("energy_I") != std::string::npos);
    CHECK(m.find("4.167") != std::string::npos);  // the G_I it would need
    CHECK(m.find("normal penalty above") != std::string::npos);
  }
  SECTION("G_II so small that shear softening snaps back") {
    auto p = rock_parameters();
    p.energy_II = 20.0;  // needs > I·max|z'|·c²h/p_t = 26.3 J/m²
    const std::string m = message(p);
    INFO(m);
    CHECK(m.find("energy_II") != std::string::npos);
    CHECK(m.find("snap-back") != std::string::npos);
    CHECK(m.find("26.2") != std::string::npos);
  }
  SECTION("other invalid values") {
    auto p = rock_parameters();
    p.tensile_strength = 0.0;
    CHECK(message(p).find("tensile_strength") != std::string::npos);
    p = rock_parameters();
    p.friction_angle_deg = 95.0;
    CHECK(message(p).find("friction_angle") != std::string::npos);
    p = rock_parameters();
    p.cohesion = -1.0;
    CHECK(message(p).find("cohesion") != std::string::npos);
    p = rock_parameters();
    p.element_size = 0.0;
    CHECK(message(p).find("element size") != std::string::npos);
    p = rock_parameters();
    p.energy_II = 0.0;
    CHECK(message(p).find("energy_II") != std::string::npos);
    p = rock_parameters();
    p.softening_a = 0.2;
    p.softening_b = 0.8;  // a + b = 1: eq. 20 undefined
    CHECK(message(p).find("a + b") != std::string::npos);
    p = rock_parameters();
    p.softening_a = -2.0;  // z rises above 1: not a softening curve
    CHECK(message(p).find("does not give a softening curve") != std::string::npos);
  }
  SECTION("valid parameters construct") {
    CHECK(message(rock_parameters()).empty());
  }
}
