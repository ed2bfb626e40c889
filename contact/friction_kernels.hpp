// Coulomb friction for one potential-contact pair: an elastic tangential spring (stick) capped
// at mu |F_n| (slip), with the spring kept in explicit per-pair history.  Pure functions.
//
// Per step, given the pair result (normal, centroid, |F_n|) and the relative velocity of the
// contactor with respect to the target at the overlap centroid:
//   1. objectivity: the spring is turned into the current tangent plane keeping its length
//      (projection + rescale; this transports it with the tilting normal), and optionally
//      rotated about the normal by the pair's mean spin;
//   2. trial:       s* = s + (v_rel - (v_rel.n) n) dt,  F* = -k s*;
//   3. return map:  if k|s*| <= mu F_n stick (s = s*), else slip: s = s* mu F_n / (k|s*|);
//   4. dissipation = slip work = |F_t| * |slip increment| = mu F_n (|s*| - mu F_n / k) (J).
// The force acts at the overlap centroid: +F_t on the contactor, -F_t on the target, spread to
// the nodes with the centroid's barycentric weights, so linear and angular momentum balance.
#pragma once

#include <cmath>
#include <string>

#include "contact/potential_contact_kernels.hpp"
#include "core/error.hpp"
#include "core/types.hpp"

namespace fdem {

struct FrictionLaw {
  double coefficient = 0.0;           // Coulomb mu (-)
  double tangential_stiffness = 0.0;  // k: stick spring of one contact pair (N/m)

  void validate() const {
    if (!(coefficient >= 0.0) || !std::isfinite(coefficient))
      throw InputError("friction coefficient must be a finite number >= 0 (got " +
                       std::to_string(coefficient) + ")");
    if (!(tangential_stiffness > 0.0) || !std::isfinite(tangential_stiffness))
      throw InputError("friction tangential stiffness must be finite and > 0 N/m (got " +
                       std::to_string(tangential_stiffness) + ")");
  }
};

// Per-pair history: the elastic tangential displacement of the stick spring (m).
struct FrictionHistory {
  Vec3 tangential_spring = Vec3::Zero();
};

struct FrictionResult {
  Vec3 force_contactor[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // N
  Vec3 force_target[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};     // N
  Vec3 tangential_force = Vec3::Zero();  // resultant on the contactor (N)
  bool slipping = false;
  double slip_dissipation = 0.0;  // J dissipated by slip during this step
  double spring_energy = 0.0;     // J stored in the spring after the step: |F_t|^2 / (2k)
  double released_energy = 0.0;   // J of spring energy dropped because the contact ended
};

// Velocity of the contactor relative to the target at the overlap centroid (m/s), interpolated
// from the node velocities with the centroid's barycentric weights.
inline Vec3 relative_velocity_at_centroid(const ContactPairResult& pair,
                                          const Vec3 (&contactor_velocity)[4],
                                          const Vec3 (&target_velocity)[4]) {
  Vec3 v = Vec3::Zero();
  for (int a = 0; a < 4; ++a) {
    v += pair.centroid_weights_contactor[a] * contactor_velocity[a];
    v -= pair.centroid_weights_target[a] * target_velocity[a];
  }
  return v;
}

// One explicit step of Coulomb friction for a pair.  `normal_spin_rate` (rad/s, optional): mean
// angular velocity of the two bodies about the normal; the spring turns with it.
inline FrictionResult coulomb_friction(const FrictionLaw& law, const ContactPairResult& pair,
                                       const Vec3& relative_velocity, double dt,
                                       FrictionHistory& history, double normal_spin_rate = 0.0) {
  FrictionResult out;
  for (int a = 0; a < 4; ++a) {
    out.force_contactor[a].setZero();
    out.force_target[a].setZero();
  }
  out.tangential_force.setZero();
  const double k = law.tangential_stiffness;
  Vec3& spring = history.tangential_spring;
  if (!pair.overlapping || !(pair.normal_force > 0.0)) {
    out.released_energy = 0.5 * k * spring.squaredNorm();
    spring.setZero();
    return out;
  }
  const Vec3& n = pair.normal;

  // 1. Objectivity: into the current tangent plane, length kept.
  const double length = spring.norm();
  Vec3 s = spring - spring.dot(n) * n;
  const double projected = s.norm();
  if (projected > 0.0) {
    s *= length / projected;
  } else {
    out.released_energy = 0.5 * k * length * length;  // spring along the new normal: no tangent
    s.setZero();
  }
  if (normal_spin_rate != 0.0) {
    const double angle = normal_spin_rate * dt;  // Rodrigues about n (s is normal to n)
    s = std::cos(angle) * s + std::sin(angle) * n.cross(s);
  }

  // 2. Trial spring from the tangential relative displacement of this step.
  const Vec3 slide = (relative_velocity - relative_velocity.dot(n) * n) * dt;
  const Vec3 trial = s + slide;
  const double trial_length = trial.norm();

  // 3. Return map onto the Coulomb cone.
  const double cap = law.coefficient * pair.normal_force;  // N
  if (k * trial_length <= cap) {
    spring = trial;
  } else {
    const double stick_length = cap / k;
    spring = trial * (stick_length / trial_length);
    out.slipping = true;
    out.slip_dissipation = cap * (trial_length - stick_length);  // 4. slip work
  }
  out.tangential_force = -k * spring;
  out.spring_energy = 0.5 * k * spring.squaredNorm();
  for (int a = 0; a < 4; ++a) {
    out.force_contactor[a] = pair.centroid_weights_contactor[a] * out.tangential_force;
    out.force_target[a] = -pair.centroid_weights_target[a] * out.tangential_force;
  }
  return out;
}

}  // namespace fdem
