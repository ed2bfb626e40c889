// Coulomb friction for one potential-contact pair: an elastic tangential spring (stick) capped
// at mu |F_n| (slip), with the spring kept in explicit per-pair history.  Pure functions.
//
// Per step, given the pair result (normal, |F_n|), the point where the spring acts and the
// relative velocity of the contactor with respect to the target at that point:
//   1. objectivity: the spring is turned into the current tangent plane keeping its length
//      (projection + rescale; this transports it with the tilting normal), and optionally
//      rotated about the normal by the pair's mean spin;
//   2. trial:       s* = s + (v_rel - (v_rel.n) n) dt,  F* = -k s*;
//   3. return map:  if k|s*| <= mu F_n stick (s = s*), else slip: s = s* mu F_n / (k|s*|);
//   4. dissipation = slip work = |F_t| * |slip increment| = mu F_n (|s*| - mu F_n / k) (J).
// The force acts at one point: +F_t on the contactor, -F_t on the target, spread to the nodes
// with that point's barycentric weights in each tet, so linear and angular momentum balance.
//
// The point.  The spring joins two material points, its anchors: attached at the overlap
// centroid in both tets (the pair's first step with a real overlap), they move with the tets, and
// the spring acts midway between them (one spatial point, so no couple).  Stuck, it then measures
// the relative displacement of material points and stores what the bodies' motion puts into it.
// Acting at the current overlap centroid instead (the spring's earlier point) it does not: that
// centroid slides across the faces with every small change of the overlap's shape, and a loaded
// spring twisted about the normal at one point and untwisted at another has turned (unit test: a
// 0.64 error of its length after a closed loop of small turns, 3e-8 at its anchors).  Under a
// sustained load this pumps energy into the contact's vibration: a column of blocks stuck on an
// incline then rings ever louder until it breaks away (docs/verification.md, "Static friction on
// an incline").  The anchors still follow the overlap centroid, with a lag (the stage's
// friction_anchor_lag, long against those vibrations), so that the spring acts where the contact
// is once the load has shifted within the pair (onto a rocking block's toe); slipping, each
// anchor moves with half the slip, so that they stay as far apart as the spring is long.
#pragma once

#include <cmath>
#include <string>

#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_overlap.hpp"
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

// Per-pair history: the elastic tangential displacement of the stick spring (m) and its anchors,
// the barycentric weights in the contactor and in the target tet of the material points it joins
// (all zero while the spring is not attached; attached weights sum to 1).
struct FrictionHistory {
  Vec3 tangential_spring = Vec3::Zero();
  double anchor_contactor[4] = {0.0, 0.0, 0.0, 0.0};
  double anchor_target[4] = {0.0, 0.0, 0.0, 0.0};

  bool attached() const {
    return anchor_contactor[0] + anchor_contactor[1] + anchor_contactor[2] + anchor_contactor[3] >
           0.0;
  }
  // Anchored at the overlap centroid of `pair` (its weights in both tets).
  void attach(const ContactPairResult& pair) {
    for (int a = 0; a < 4; ++a) {
      anchor_contactor[a] = pair.centroid_weights_contactor[a];
      anchor_target[a] = pair.centroid_weights_target[a];
    }
  }
  // The anchors move the `fraction` (0–1) of their way to the overlap centroid of `pair`.
  void follow(const ContactPairResult& pair, double fraction) {
    for (int a = 0; a < 4; ++a) {
      anchor_contactor[a] += fraction * (pair.centroid_weights_contactor[a] - anchor_contactor[a]);
      anchor_target[a] += fraction * (pair.centroid_weights_target[a] - anchor_target[a]);
    }
  }
  void detach() {
    tangential_spring.setZero();
    for (int a = 0; a < 4; ++a) anchor_contactor[a] = anchor_target[a] = 0.0;
  }
};

// Where a pair's friction acts: one point, as its barycentric weights in the contactor and in
// the target tet.
struct FrictionPoint {
  double contactor[4] = {0.0, 0.0, 0.0, 0.0};
  double target[4] = {0.0, 0.0, 0.0, 0.0};
};

// The overlap centroid of `pair`.
inline FrictionPoint centroid_point(const ContactPairResult& pair) {
  FrictionPoint p;
  for (int a = 0; a < 4; ++a) {
    p.contactor[a] = pair.centroid_weights_contactor[a];
    p.target[a] = pair.centroid_weights_target[a];
  }
  return p;
}

// The point of an attached spring: midway between its anchors at the tets' current positions
// (TetGeometry: corners and barycentric gradients, which do not depend on the map's origin).
// False (and `point` untouched) for a degenerate tet, which has no barycentric coordinates.
inline bool spring_point(const FrictionHistory& history, const TetGeometry& contactor,
                         const TetGeometry& target, FrictionPoint& point) {
  Vec3 anchor_c = Vec3::Zero(), anchor_t = Vec3::Zero();
  for (int a = 0; a < 4; ++a) {
    anchor_c += history.anchor_contactor[a] * contactor.corners.x[a];
    anchor_t += history.anchor_target[a] * target.corners.x[a];
  }
  const Vec3 middle = 0.5 * (anchor_c + anchor_t);
  double at_c[4], at_t[4];
  if (!contactor.valid || !target.valid ||
      !barycentric_values(contactor.gradient, contactor.corners.x[0], middle, at_c) ||
      !barycentric_values(target.gradient, target.corners.x[0], middle, at_t))
    return false;
  for (int a = 0; a < 4; ++a) {
    point.contactor[a] = at_c[a];
    point.target[a] = at_t[a];
  }
  return true;
}

inline bool spring_point(const FrictionHistory& history, const TetCorners& contactor,
                         const TetCorners& target, FrictionPoint& point) {
  TetGeometry geometry_c, geometry_t;
  compute_tet_geometry(contactor, geometry_c, false);
  compute_tet_geometry(target, geometry_t, false);
  return spring_point(history, geometry_c, geometry_t, point);
}

// A slipping spring's anchors follow the slip: the contactor's moves back by half the relative
// displacement `slip` (m) that the spring did not take up, the target's forward by half, so that
// they stay as far apart as the spring is long.
inline void slide_anchors(FrictionHistory& history, const TetGeometry& contactor,
                          const TetGeometry& target, const Vec3& slip) {
  for (int a = 0; a < 4; ++a) {  // barycentric coordinates are affine: shift = gradient · move
    history.anchor_contactor[a] -= 0.5 * contactor.gradient[a].dot(slip);
    history.anchor_target[a] += 0.5 * target.gradient[a].dot(slip);
  }
}

// Velocity of the contactor relative to the target at `point` (m/s), interpolated from the node
// velocities with the point's barycentric weights.
inline Vec3 relative_velocity_at(const FrictionPoint& point, const Vec3 (&contactor_velocity)[4],
                                 const Vec3 (&target_velocity)[4]) {
  Vec3 v = Vec3::Zero();
  for (int a = 0; a < 4; ++a) {
    v += point.contactor[a] * contactor_velocity[a];
    v -= point.target[a] * target_velocity[a];
  }
  return v;
}

struct FrictionResult {
  Vec3 force_contactor[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // N
  Vec3 force_target[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};     // N
  Vec3 tangential_force = Vec3::Zero();  // resultant on the contactor (N)
  bool slipping = false;
  double slip_dissipation = 0.0;  // J dissipated by slip during this step
  double spring_energy = 0.0;     // J stored in the spring after the step: |F_t|^2 / (2k)
  double released_energy = 0.0;   // J of spring energy dropped because the contact ended
  Vec3 slip = Vec3::Zero();       // relative displacement slipped during this step (m)
};

// Velocity of the contactor relative to the target at the overlap centroid (m/s).
inline Vec3 relative_velocity_at_centroid(const ContactPairResult& pair,
                                          const Vec3 (&contactor_velocity)[4],
                                          const Vec3 (&target_velocity)[4]) {
  return relative_velocity_at(centroid_point(pair), contactor_velocity, target_velocity);
}

// One explicit step of Coulomb friction for a pair, acting at `point` (`relative_velocity` is
// taken there).  `normal_spin_rate` (rad/s, optional): mean angular velocity of the two bodies
// about the normal; the spring turns with it.  A contact that ended detaches the spring.
inline FrictionResult coulomb_friction(const FrictionLaw& law, const ContactPairResult& pair,
                                       const FrictionPoint& point, const Vec3& relative_velocity,
                                       double dt, FrictionHistory& history,
                                       double normal_spin_rate = 0.0) {
  FrictionResult out;  // (zero forces)
  const double k = law.tangential_stiffness;
  Vec3& spring = history.tangential_spring;
  if (!pair.overlapping || !(pair.normal_force > 0.0)) {
    out.released_energy = 0.5 * k * spring.squaredNorm();
    history.detach();
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
    out.slip = trial - spring;
    out.slip_dissipation = cap * (trial_length - stick_length);  // 4. slip work
  }
  out.tangential_force = -k * spring;
  out.spring_energy = 0.5 * k * spring.squaredNorm();
  for (int a = 0; a < 4; ++a) {
    out.force_contactor[a] = point.contactor[a] * out.tangential_force;
    out.force_target[a] = -point.target[a] * out.tangential_force;
  }
  return out;
}

// The same step acting at the overlap centroid (a single pair without tets' positions: the
// return map's tests).
inline FrictionResult coulomb_friction(const FrictionLaw& law, const ContactPairResult& pair,
                                       const Vec3& relative_velocity, double dt,
                                       FrictionHistory& history, double normal_spin_rate = 0.0) {
  return coulomb_friction(law, pair, centroid_point(pair), relative_velocity, dt, history,
                          normal_spin_rate);
}

}  // namespace fdem
