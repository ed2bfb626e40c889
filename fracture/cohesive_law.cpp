#include "fracture/cohesive_law.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace fdem {

namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

[[noreturn]] void reject(const std::string& what) {
  throw InputError("fracture: " + what);
}

// Composite 5-point Gauss–Legendre rule on [0, 1]: exact to ~1e-15 for the smooth z(D).
template <class F>
double integrate_unit(const F& f, int panels) {
  static const double node[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                 0.9061798459386640};
  static const double weight[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                   0.4786286704993665, 0.2369268850561891};
  const double width = 1.0 / panels;
  double sum = 0.0;
  for (int p = 0; p < panels; ++p) {
    const double mid = (p + 0.5) * width;
    double panel = 0.0;
    for (int k = 0; k < 5; ++k) panel += weight[k] * f(mid + 0.5 * width * node[k]);
    sum += 0.5 * width * panel;
  }
  return sum;
}

}  // namespace

SofteningCurve::SofteningCurve(double a, double b, double c) : a_(a), b_(b), c_(c) {
  const std::string abc = "softening {a: " + fmt(a) + ", b: " + fmt(b) + ", c: " + fmt(c) + "}";
  if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c)) reject(abc + " must be finite");
  if (c < 1.0)
    reject(abc +
           ": c must be ≥ 1 so that z(D) reaches 0 at D = 1 with a finite slope "
           "(the usual value is 6.0)");
  const double sum = a + b;
  if (std::abs(sum) < 1e-9 || std::abs(1.0 - sum) < 1e-9)
    reject(abc + ": a + b must differ from 0 and 1 (eq. 20 divides by a+b and 1−a−b)");
  amp_ = (sum - 1.0) / sum;
  rate_ = (a + c * b) / (sum * (1.0 - sum));

  // z must fall monotonically from z(0) = 1 to z(1) = 0 and stay in [0, 1].
  const int samples = 20000;
  double previous = z(0.0);
  for (int i = 0; i <= samples; ++i) {
    const double D = static_cast<double>(i) / samples;
    const double value = i == samples ? 0.0
                                      : (1.0 - amp_ * std::exp(rate_ * D)) *
                                            (a * (1.0 - D) + b * std::pow(1.0 - D, c));
    if (!(value >= -1e-12 && value <= 1.0 + 1e-12) || value > previous + 1e-12) {
      reject(abc + " does not give a softening curve: z(" + fmt(D) + ") = " + fmt(value) +
             " (z must decrease monotonically from 1 at D = 0 to 0 at D = 1; the defaults "
             "a = 0.63, b = 1.8, c = 6.0 fit concrete and rock)");
    }
    previous = value;
    max_slope_ = std::max(max_slope_, -dz(std::min(D, 1.0)));
  }
  integral_ = integrate_unit([this](double D) { return z(D); }, 2000);
}

PenaltyBounds minimum_penalties(const CohesiveParameters& p, const SofteningCurve& curve) {
  PenaltyBounds b;
  b.normal = p.tensile_strength * p.tensile_strength * p.element_size / (2.0 * p.energy_I);
  if (p.cohesion > 0.0)
    b.tangential = curve.integral() * curve.max_slope() * p.cohesion * p.cohesion * p.element_size /
                   p.energy_II;
  return b;
}

CohesiveLaw::CohesiveLaw(const CohesiveParameters& p)
    : CohesiveLaw(p, SofteningCurve(p.softening_a, p.softening_b, p.softening_c)) {}

CohesiveLaw::CohesiveLaw(const CohesiveParameters& p, const SofteningCurve& curve)
    : params_(p), curve_(curve) {
  FDEM_VERIFY(
      curve.a() == p.softening_a && curve.b() == p.softening_b && curve.c() == p.softening_c,
      "the softening curve of the parameters");
  auto positive = [](double v, const char* name, const char* unit) {
    if (!(std::isfinite(v) && v > 0.0))
      reject(std::string(name) + " must be a positive number (" + unit + "), got " + fmt(v));
  };
  positive(p.tensile_strength, "tensile_strength",
           "Pa; a joint without tensile strength is a contact: leave the faces unjoined");
  positive(p.energy_I, "energy_I", "J/m^2");
  positive(p.normal_penalty, "normal penalty", "Pa");
  positive(p.tangential_penalty, "tangential penalty", "Pa");
  positive(p.element_size, "element size h", "m");
  if (!(std::isfinite(p.cohesion) && p.cohesion >= 0.0))
    reject("cohesion must be ≥ 0 Pa (0 gives a dry, purely frictional joint), got " +
           fmt(p.cohesion));
  if (!(p.friction_angle_deg >= 0.0 && p.friction_angle_deg < 90.0))
    reject("friction_angle must be in [0, 90) degrees, got " + fmt(p.friction_angle_deg));

  constexpr double pi = 3.14159265358979323846;
  tan_phi_ = std::tan(p.friction_angle_deg * pi / 180.0);
  k_n_ = p.normal_penalty / p.element_size;
  k_t_ = p.tangential_penalty / p.element_size;
  const double I = curve_.integral();

  // Mode I: G_I = ½·f_t·δt + I·f_t·(δc − δt): the pre-peak penalty energy must fit inside G_I.
  delta_t_ = p.tensile_strength / k_n_;
  const double pre_peak = 0.5 * p.tensile_strength * delta_t_;
  if (!(p.energy_I > pre_peak * (1.0 + 1e-9))) {
    reject("energy_I = " + fmt(p.energy_I) +
           " J/m^2 is smaller than the energy ½·f_t²·h/p_n = " + fmt(pre_peak) +
           " J/m^2 the penalty stores before the peak (δc would be ≤ δt = " + fmt(delta_t_) +
           " m). Use energy_I > " + fmt(pre_peak) + " J/m^2, or raise the normal penalty above " +
           fmt(p.tensile_strength * p.tensile_strength * p.element_size / (2.0 * p.energy_I)) +
           " Pa, or use elements smaller than h = " +
           fmt(2.0 * p.energy_I * p.normal_penalty / (p.tensile_strength * p.tensile_strength)) +
           " m");
  }
  delta_c_ = delta_t_ + (p.energy_I - pre_peak) / (I * p.tensile_strength);
  inv_opening_range_ = 1.0 / (delta_c_ - delta_t_);

  // Mode II: the cohesive part softens with the plastic slip κ, G_II = I·c·s_c.  The softening
  // must not be steeper than the tangential penalty (snap-back: no unique slip for a given
  // sliding): s_c > max|z'|·c/k_t.
  if (p.cohesion > 0.0) {
    positive(p.energy_II, "energy_II", "J/m^2 (needed when cohesion > 0)");
    slip_c_ = p.energy_II / (I * p.cohesion);
    const double needed = I * curve_.max_slope() * p.cohesion * p.cohesion / k_t_;
    if (!(p.energy_II > needed * (1.0 + 1e-9))) {
      reject("energy_II = " + fmt(p.energy_II) +
             " J/m^2 is too small for the tangential penalty: the shear softening would be "
             "steeper than the elastic slope (snap-back). Use energy_II > " +
             fmt(needed) + " J/m^2, or raise the tangential penalty above " +
             fmt(I * curve_.max_slope() * p.cohesion * p.cohesion * p.element_size / p.energy_II) +
             " Pa, or use elements smaller than h = " +
             fmt(p.energy_II * p.tangential_penalty /
                 (I * curve_.max_slope() * p.cohesion * p.cohesion)) +
             " m");
    }
    inv_slip_c_ = 1.0 / slip_c_;
  } else {
    slip_c_ = std::numeric_limits<double>::infinity();
    inv_slip_c_ = 0.0;  // no cohesion: slip is pure friction and never damages
  }
}

double CohesiveLaw::solve_slip(double trial, double x_lo, double opening_ratio, double kappa,
                               double friction_stress) const {
  const double c = params_.cohesion;
  if (c == 0.0) return x_lo;  // perfect Coulomb plasticity: closed form
  // g(x) = k_t(E − x) − c·z(D(κ+x)) − σc·tanφ decreases strictly (validated: s_c > max|z'|c/k_t).
  auto g = [&](double x, double& slope) {
    const double s = (kappa + x) * inv_slip_c_;
    const double D2 = opening_ratio * opening_ratio + s * s;
    double D = std::sqrt(D2);
    double dD = 0.0;
    if (D >= 1.0) {
      D = 1.0;
    } else if (D > 0.0) {
      dD = s * inv_slip_c_ / D;
    }
    slope = -k_t_ - c * curve_.dz(D) * dD;
    return k_t_ * (trial - x) - c * curve_.z(D) - friction_stress;
  };
  double lo = x_lo, hi = trial;
  double slope;
  double x = lo;
  double gx = g(x, slope);
  if (gx <= 0.0) return x;
  const double tol = 1e-15 * std::max(trial, kappa + trial);
  for (int it = 0; it < 100; ++it) {
    if (gx > 0.0)
      lo = x;
    else
      hi = x;
    double next = x - gx / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket: bisect
    if (std::abs(next - x) <= tol || hi - lo <= tol) return next;
    x = next;
    gx = g(x, slope);
    if (gx == 0.0) return x;
  }
  return x;
}

}  // namespace fdem
