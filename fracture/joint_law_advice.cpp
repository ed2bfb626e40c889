#include "fracture/joint_law_advice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace fdem {

namespace {

std::string fmt(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

// A value to type into the scene: 2 % above x, rounded up to two significant digits.
double round_up(double x) {
  const double y = 1.02 * x;
  const double unit = std::pow(10.0, std::floor(std::log10(y)) - 1.0);
  return std::ceil(y / unit) * unit;
}

// A value that must stay below x: 2 % under it, rounded down to two significant digits.
double round_down(double x) {
  const double y = 0.98 * x;
  const double unit = std::pow(10.0, std::floor(std::log10(y)) - 1.0);
  return std::floor(y / unit) * unit;
}

// The block's limits over all its laws (element sizes and strength factors).
struct BlockLimits {
  double penalty_normal = 0.0, penalty_tangential = 0.0;          // Pa needed (strictly above)
  double energy_I = 0.0, energy_II = 0.0;                         // J/m² needed (strictly above)
  double element_size = std::numeric_limits<double>::infinity();  // m: works below
  double largest_size = 0.0;                                      // m, of the block's joints
  double strongest = 0.0;                                         // largest strength factor
};

BlockLimits block_limits(const std::vector<JointLawSpec>& laws, const std::string& origin,
                         const SofteningCurve& curve) {
  BlockLimits b;
  const double slope = curve.integral() * curve.max_slope();  // I·max|z′|
  for (const JointLawSpec& l : laws) {
    if (l.origin != origin) continue;
    const CohesiveParameters p = cohesive_parameters(l);
    const PenaltyBounds need = minimum_penalties(p, curve);
    const double f2 = p.tensile_strength * p.tensile_strength, c2 = p.cohesion * p.cohesion;
    b.penalty_normal = std::max(b.penalty_normal, need.normal);
    b.penalty_tangential = std::max(b.penalty_tangential, need.tangential);
    b.energy_I = std::max(b.energy_I, 0.5 * f2 * p.element_size / p.normal_penalty);
    b.element_size = std::min(b.element_size, 2.0 * p.energy_I * p.normal_penalty / f2);
    if (p.cohesion > 0.0) {
      b.energy_II = std::max(b.energy_II, slope * c2 * p.element_size / p.tangential_penalty);
      b.element_size = std::min(b.element_size, p.energy_II * p.tangential_penalty / (slope * c2));
    }
    b.largest_size = std::max(b.largest_size, l.element_size);
    b.strongest = std::max(b.strongest, l.strength_scale);
  }
  return b;
}

}  // namespace

CohesiveParameters cohesive_parameters(const JointLawSpec& spec) {
  CohesiveParameters p;
  p.tensile_strength = spec.fracture.tensile_strength;
  p.cohesion = spec.fracture.cohesion;
  p.friction_angle_deg = spec.fracture.friction_angle_deg;
  p.energy_I = spec.fracture.energy_I;
  p.energy_II = spec.fracture.energy_II;
  p.normal_penalty = spec.normal_penalty;
  p.tangential_penalty = spec.tangential_penalty;
  p.element_size = spec.element_size;
  p.softening_a = spec.fracture.softening_a;
  p.softening_b = spec.fracture.softening_b;
  p.softening_c = spec.fracture.softening_c;
  return p;
}

std::string joint_law_message(const std::vector<JointLawSpec>& laws, std::size_t failed,
                              const SofteningCurve& curve, const std::string& what) {
  const JointLawSpec& bad = laws[failed];
  const FractureSpec& f = bad.fracture;
  const BlockLimits b = block_limits(laws, bad.origin, curve);
  const bool normal = !(bad.normal_penalty > b.penalty_normal * (1.0 + 1e-9));
  const bool shear =
      f.cohesion > 0.0 && !(bad.tangential_penalty > b.penalty_tangential * (1.0 + 1e-9));
  if (!normal && !shear)
    return bad.origin + " (joints with element size h = " + std::to_string(bad.element_size) +
           " m, penalty " + std::to_string(bad.normal_penalty) + " Pa): " + what;

  const std::string key = f.key.empty() ? "fracture" : f.key;
  const double scale = bad.strength_scale;  // the block's values are the law's over its factor
  const std::string spread = b.strongest != 1.0 ? " × strength factor up to " + fmt(b.strongest) +
                                                      " (strength_distribution)"
                                                : "";
  const auto penalty_text = [&](double p) {
    return fmt(p) + " Pa" + (p == bad.auto_penalty ? " (auto: 50·E)" : "");
  };
  std::ostringstream m;
  if (!f.location.empty()) m << f.location << ": ";
  m << key << ": the joints of " << bad.origin
    << " cannot work with the joint penalty p_n = " << penalty_text(bad.normal_penalty)
    << ", p_t = " << penalty_text(bad.tangential_penalty) << ".";
  if (shear)
    m << " Shear would snap back: after the peak the cohesion softens over the slip faster than "
         "the joint's elastic slope p_t/h unloads, unless energy_II > I·max|z′|·c²·h/p_t (I = "
      << fmt(curve.integral(), 4) << " and max|z′| = " << fmt(curve.max_slope(), 4)
      << " of the softening curve); with c = " << fmt(f.cohesion / scale) << " Pa" << spread
      << " and joints up to h = " << fmt(b.largest_size) << " m that is " << fmt(b.energy_II)
      << " J/m², but energy_II = " << fmt(f.energy_II) << " J/m².";
  if (normal)
    m << " Before the peak the penalty stores ½·f_t²·h/p_n, which must stay below energy_I; with "
         "f_t = "
      << fmt(f.tensile_strength / scale) << " Pa" << spread
      << " and joints up to h = " << fmt(b.largest_size) << " m that is " << fmt(b.energy_I)
      << " J/m², but energy_I = " << fmt(f.energy_I) << " J/m².";
  const double need = std::max(b.penalty_normal, b.penalty_tangential);  // one value sets both
  m << " Any one of these works: set " << key << ".penalty: " << fmt(round_up(need), 2)
    << " (Pa; valid: any value above " << fmt(need) << " Pa — a stiffer joint shortens the stable "
    << "time step as 1/√penalty; auto = 50·E = " << fmt(bad.auto_penalty) << " Pa); or raise";
  if (shear) m << " energy_II above " << fmt(b.energy_II) << " J/m²";
  if (shear && normal) m << " and";
  if (normal) m << " energy_I above " << fmt(b.energy_I) << " J/m²";
  m << "; or refine the mesh where the joints are, so that the joint element size h (the mean of "
       "the two tets' altitudes onto a joint face) stays below "
    << fmt(round_down(b.element_size), 2) << " m (now up to " << fmt(b.largest_size) << " m).";
  return m.str();
}

}  // namespace fdem
