// Potential-based tet-tet contact (Munjiza & Andrews 2000) with exactly conservative nodal
// forces.  Pure per-pair functions: no allocation, no state.
//
// Each tet carries the potential phi(x) = 4 min_k lambda_k(x): 1 at the centroid, 0 on the faces,
// linear in each of the four sub-tets (centroid + one face).  For a pair (contactor c, target t)
// with overlap Omega = c ∩ t the contact energy is
//     U = p ∫_Omega (phi_c + phi_t) dV                                   (p: penalty, Pa; U: J)
// and the nodal forces are its exact negative gradient (Reynolds transport; phi_t vanishes on the
// target's faces, phi_c on the contactor's):
//     f_t,b = p ∫_Omega lambda_b^t grad phi_t dV - p ∫_{dOmega ∩ dt} phi_c lambda_b^t n dS
//     f_c,a = p ∫_Omega lambda_a^c grad phi_c dV - p ∫_{dOmega ∩ dc} phi_t lambda_a^c n dS
// so the resultant on the contactor is p ∫_Omega (grad phi_c - grad phi_t) dV and the contact
// does no net work over a closed path.
//
// Evaluation: Omega is split into the four pieces (sub-tet of c) ∩ t and, independently, the four
// pieces (sub-tet of t) ∩ c.  Each piece is a sub-tet clipped by the other tet's four face
// planes with a vertex-graph convex clipper (every vertex classified once, every cut edge
// computed once, so the pieces are closed and shared faces identical: robust for touching and
// coplanar configurations).  Volume integrals of linear functions are exact cone sums from a
// vertex of the piece; surface integrals of the quadratic phi*lambda over the pieces' faces on
// the other tet's faces use the exact degree-2 triangle rule.  Everything is computed in the
// piece's own barycentric coordinates (the sub-tets are fixed shapes there) and mapped once.
#pragma once

#include <algorithm>

#include "contact/tet_overlap.hpp"
#include "core/types.hpp"

namespace fdem {

struct ContactPairResult {
  bool overlapping = false;  // false: every output below is zero
  double energy = 0.0;       // U (J)
  Vec3 force_contactor[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(),
                             Vec3::Zero()};  // N, on the contactor's nodes
  Vec3 force_target[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(),
                          Vec3::Zero()};  // N, on the target's nodes
  double overlap_volume = 0.0;            // m^3
  Vec3 normal = Vec3::Zero();             // unit direction of the resultant force on the contactor
                               // (zero when that resultant vanishes, e.g. coincident tets)
  Vec3 centroid = Vec3::Zero();                         // overlap centroid (m): where friction acts
  double normal_force = 0.0;                            // |resultant force on the contactor| (N)
  double centroid_weights_contactor[4] = {0, 0, 0, 0};  // barycentric coords of centroid in c
  double centroid_weights_target[4] = {0, 0, 0, 0};     // barycentric coords of centroid in t
};

// The largest nodal force of a pair result (N), and the largest difference between the nodal
// forces of two results of the same pair (N): for comparing kernels and tolerances.
inline double largest_nodal_force(const ContactPairResult& r) {
  double largest = 0.0;
  for (int v = 0; v < 4; ++v)
    largest = std::max({largest, r.force_contactor[v].norm(), r.force_target[v].norm()});
  return largest;
}
inline double largest_nodal_force_difference(const ContactPairResult& a,
                                             const ContactPairResult& b) {
  double largest = 0.0;
  for (int v = 0; v < 4; ++v)
    largest = std::max({largest, (a.force_contactor[v] - b.force_contactor[v]).norm(),
                        (a.force_target[v] - b.force_target[v]).norm()});
  return largest;
}

// Cheap rejection (boxes, face planes), then the exact integration.  penalty in Pa.  With
// sliver_tolerance > 0, a pair whose nodal forces are proven below sliver_tolerance · p · ℓ²
// (pair_force_bound.hpp; ℓ the shorter tet's longest edge) is returned as not overlapping: the
// slivers next to a pressed pair across an interface, which carry O(depth/size) of its force.
// Of the other pairs, the pieces proven below the same limit are left out (the sub-tets beside a
// pressed face, whose overlap is a sliver along the face's edges), each with the flux it leaves
// uncancelled: the forces stay the exact gradient of the energy.
ContactPairResult potential_contact(const TetCorners& contactor, const TetCorners& target,
                                    double penalty, double sliver_tolerance = 0.0);

// potential_contact without the sliver skip and with the pieces in `left_out` left out (bit
// 4T + i: sub-tet i of tet T, 0 contactor, 1 target, clipped by the other tet), each with the flux
// it leaves uncancelled, so that the forces are the exact gradient of the kept pieces' energy;
// for the tests of the piece bound.
ContactPairResult potential_contact_without(const TetCorners& contactor, const TetCorners& target,
                                            double penalty, unsigned left_out);

// The same with the contactor prepared once for all its pairs and the target's geometry computed
// once for all of its (tet_overlap.hpp): bit for bit.  With a memo, the pieces' clips are
// replayed from the pair's record of the step before where they cut the same vertices, and
// recorded for the next step (clip_replay.hpp): bit for bit too, whatever the record holds.
struct ClipMemo;
ContactPairResult potential_contact(const PreparedContactor& contactor, const TetGeometry& target,
                                    double penalty, double sliver_tolerance = 0.0,
                                    ClipMemo* memo = nullptr);

// The exact integration alone, with only the degenerate-tet check (no box or face-plane
// rejection).  Same results as potential_contact for every pair that passes the rejection;
// exposed to test that the rejection is conservative.
ContactPairResult potential_contact_unculled(const TetCorners& contactor, const TetCorners& target,
                                             double penalty);

// The previous implementation (contact/potential_contact_baseline.cpp), kept as the baseline the
// benchmarks measure against; same results to round-off.
ContactPairResult potential_contact_baseline(const TetCorners& contactor, const TetCorners& target,
                                             double penalty);

// Exact integral over one tet of its own potential: ∫ 4 min(lambda) dV = V/4 (m^3).
inline double tet_potential_integral(double volume) {
  return 0.25 * volume;
}

}  // namespace fdem
