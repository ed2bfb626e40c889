// The cheap end of the verification suite (benchmarks/bench_verification.cpp, docs/verification.md)
// for the reference problems that the other verification tests do not cover: uniaxial compression
// between frictionless platens (docs/references.md 14) and the free–free bending frequency of a
// beam of linear tetrahedra against h (docs/references.md 5, shear locking).
#include <catch2/catch.hpp>
#include <cmath>

#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

void set_body_velocity(Model& model, int body, const Vec3& v) {
  model.nodes.keep_prescribed_velocities();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces[model.nodes.piece[n]].body == body)
      vec3_at(model.nodes.prescribed_velocity.data(), n) = v;
}

// Σ −f over the prescribed nodes of a body: the force its loading device applies (N).
Vec3 reaction_on_body(const Model& model, int body) {
  Vec3 r = Vec3::Zero();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces[model.nodes.piece[n]].body == body && model.nodes.constrained[n])
      r -= vec3_at(model.nodes.f.data(), n);
  return r;
}

// Mean coordinate k of the nodes of `body` whose reference coordinate k is `at` (m).
double face_position(const Model& model, int body, int k, double at) {
  double sum = 0;
  int n = 0;
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    if (model.pieces[model.nodes.piece[i]].body == body &&
        std::abs(model.nodes.x0(i)[k] - at) < 1e-9) {
      sum += model.nodes.x[3 * i + k];
      ++n;
    }
  return sum / n;
}

double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / x.size(), my += y[i] / x.size();
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxy / sxx;
}

struct Compression {
  double young = 0, poisson = 0, balance = 0;
};

// A 0.1 × 0.1 × 0.2 m prism (n × n × 2n cells) between two wider platens with friction 0; the lower
// platen fixed, the upper one pushed down at a speed rising smoothly (sin²) to 0.02 m/s over 8
// P-wave transits.  E = σ/ε_z and ν = −ε_x/ε_z as least-squares slopes over the second half of 20
// transits; σ from the upper platen's reaction, strains from the prism's own faces.
Compression uniaxial_compression(int n, double safety) {
  const double E = 30e9, nu = 0.2, rho = 2500, a = 0.1, H = 0.2, v = 0.02, overhang = 0.02;
  const double c_p = std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
  const double ramp = 8 * H / c_p, end_time = 20 * H / c_p;
  Scene scene = basic_scene(end_time);
  // St. Venant–Kirchhoff: zero energy at F = I (the neo-Hookean one is round-off ~1e-16·E·V, which
  // the energy check compares with the first, tiny loads).
  scene.materials.push_back(elastic_material(rho, E, nu, ElasticModel::st_venant_kirchhoff));
  scene.materials[0].contact.friction = 0.0;
  scene.time.safety = safety;
  scene.bodies.push_back(box_body("lower_platen", Vec3(-overhang, -overhang, -0.02),
                                  Vec3(a + overhang, a + overhang, 0), n + 2, n + 2, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(box_body("prism", Vec3(0, 0, 0), Vec3(a, a, H), n, n, 2 * n));
  scene.bodies.push_back(box_body("upper_platen", Vec3(-overhang, -overhang, H),
                                  Vec3(a + overhang, a + overhang, H + 0.02), n + 2, n + 2, 1));
  LoadSpec push;
  push.bodies = {2};
  push.velocity = Vec3::Zero();
  scene.loads.push_back(push);
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  std::vector<double> ez, ex, sigma;
  Compression out;
  while (sim->time() < end_time) {
    const double t = sim->time() + 0.5 * sim->time_step();
    const double rise = t < ramp ? std::pow(std::sin(0.5 * M_PI * t / ramp), 2) : 1.0;
    set_body_velocity(model, 2, Vec3(0, 0, -v * rise));
    sim->step();
    out.balance = std::max(out.balance, sim->energy().balance_error());
    if (sim->time() < 0.5 * end_time) continue;
    ez.push_back((face_position(model, 1, 2, H) - face_position(model, 1, 2, 0)) / H - 1);
    ex.push_back((face_position(model, 1, 0, a) - face_position(model, 1, 0, 0)) / a - 1);
    sigma.push_back(reaction_on_body(model, 2).z() / (a * a));
  }
  out.young = slope(ez, sigma);  // both negative: shortening, the device pushing down
  out.poisson = -slope(ez, ex);
  return out;
}

// First free–free bending frequency (Hz) of a 2.0 × 0.1 × 0.1 m beam (E = 30 GPa, ρ = 2500,
// ν = 0) of n_x × n × n cells, started with the Euler–Bernoulli mode shape as velocity along z;
// from the zero crossings of the mid-span deflection relative to the ends.
double bending_frequency(int nx, int n, double periods, double exact) {
  const double L = 2.0, a = 0.1, beta = 4.730040745 / L;
  Scene scene = basic_scene(periods / exact);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.0, ElasticModel::st_venant_kirchhoff));
  scene.time.safety = 0.9;
  scene.bodies.push_back(box_body("beam", Vec3(0, 0, 0), Vec3(L, a, a), nx, n, n));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  const double bl = beta * L;
  const double s = (std::cosh(bl) - std::cos(bl)) / (std::sinh(bl) - std::sin(bl));
  for (LocalIndex i = 0; i < model.nodes.size(); ++i) {
    const double x = beta * model.nodes.x0(i)[0];
    model.nodes.v[3 * i + 2] =
        1e-3 * (std::cosh(x) + std::cos(x) - s * (std::sinh(x) + std::sin(x)));
  }
  std::vector<double> crossings;
  double previous = 0, previous_time = 0;
  while (sim->time() < scene.time.end) {
    sim->step();
    double mid = 0, ends = 0;
    int n_mid = 0, n_ends = 0;
    for (LocalIndex i = 0; i < model.nodes.size(); ++i) {
      const double X = model.nodes.x0(i)[0];
      const double w = model.nodes.x[3 * i + 2] - model.nodes.x0(i)[2];
      if (std::abs(X - L / 2) < 1e-9) mid += w, ++n_mid;
      if (X == 0 || X == L) ends += w, ++n_ends;
    }
    const double now = mid / n_mid - ends / n_ends;
    if (sim->steps_done() > 1 && (now < 0) != (previous < 0))
      crossings.push_back(previous_time +
                          (sim->time() - previous_time) * previous / (previous - now));
    previous = now;
    previous_time = sim->time();
  }
  REQUIRE(crossings.size() >= 3);
  return 0.5 * (crossings.size() - 1) / (crossings.back() - crossings.front());
}

}  // namespace

TEST_CASE(
    "uniaxial compression between frictionless platens: apparent E and ν within 1 % "
    "(docs/references.md 14)",
    "[verification][contact]") {
  const Compression c = uniaxial_compression(1, 0.9);
  INFO("apparent E " << c.young << " Pa, ν " << c.poisson << ", worst balance " << c.balance);
  CHECK(std::abs(c.young / 30e9 - 1) < 0.01);
  CHECK(std::abs(c.poisson / 0.2 - 1) < 0.01);
  CHECK(c.balance < 0.01);
}

TEST_CASE(
    "free-free bending frequency of a tetrahedral beam converges from above as h falls "
    "(docs/references.md 5)",
    "[verification]") {
  // Euler–Bernoulli: f = (β₁L)²/(2πL²)·√(EI/ρA) = 89.03 Hz with β₁L = 4.7300.
  const double exact =
      4.730040745 * 4.730040745 / (2 * M_PI * 4.0) * std::sqrt(30e9 * 0.01 / (12 * 2500));
  const double coarse = bending_frequency(20, 1, 2.0, exact);
  const double fine = bending_frequency(40, 2, 2.0, exact);
  const double e_coarse = coarse / exact - 1, e_fine = fine / exact - 1;
  INFO("20x1x1 cells: " << coarse << " Hz (error " << e_coarse << "); 40x2x2 cells: " << fine
                        << " Hz (error " << e_fine << "); exact " << exact << " Hz");
  // Linear tets are too stiff in bending (locking): the error is positive and falls with h.
  CHECK(e_coarse > 0);
  CHECK(e_fine > 0);
  CHECK(e_fine < 0.6 * e_coarse);
}
