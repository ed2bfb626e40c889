// A cheap, rigorous upper bound of what one potential-contact pair can contribute, from the
// quantities the face-plane rejection already computed.  Used to skip pairs whose overlap is a
// sliver thin in two directions (the tets next to a pressed pair across an interface, sharing
// only an edge or a corner of its footprint): their forces are O(depth/size) of the pressed
// pair's and they cost a full clip each.
//
// The overlap Omega = c ∩ t lies in a slab per face a of either tet T:
//     0 <= lambda_a^T <= mu_a^T,   mu_a^T = max over the other tet's corners of lambda_a^T,
// because Omega ⊂ T and Omega ⊂ the other tet (a convex hull, on which a linear function peaks at
// a corner).  Two slabs A, B with non-parallel gradients g_A, g_B meet in a prism along
// g_A × g_B whose cross-section is a parallelogram of area mu_A mu_B / |g_A × g_B| and perimeter
// 2 (mu_A |g_B| + mu_B |g_A|) / |g_A × g_B|; along the prism Omega is no longer than the shorter
// tet's longest edge W.  Three slabs with independent gradients meet in a parallelepiped, which
// is thin in all three directions where a corner of one tet pokes into the other.  These bound
// Omega's volume V and (a convex set inside a convex set has the smaller surface) the area S of
// its boundary.  On Omega the potentials are bounded too:
// phi_T = 4 min_a lambda_a^T <= 4 min_a mu_a^T =: Phi_T.
//
// With the force formulas of potential_contact_kernels.hpp, every nodal force of tet T obeys
//     |f_T,b| <= p (4 G_T V + Phi_other S),   G_T = max_a |grad lambda_a^T|,
// and the energy U = p ∫ (phi_c + phi_t) dV <= p V (Phi_c + Phi_t).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/tet_overlap.hpp"
#include "core/lanes.hpp"

namespace fdem {

struct PairForceBound {
  double nodal_force = 0.0;  // N: no nodal force of either tet exceeds it
  double energy = 0.0;       // J
  double volume = 0.0;       // m^3: the overlap's volume is below it
  double surface = 0.0;      // m^2: the area of the overlap's boundary is below it
  double length = 0.0;       // m: the shorter of the two tets' longest edges
};

// Prisms are formed from slabs thinner than this (barycentric units) only: a thicker slab's prism
// is rarely the smallest, and each costs a cross product and a square root.
constexpr double kPrismSlab = 1e-2;
constexpr int kMaxThinSlabs = 4;

// The slab depths mu[4T + a] (face a of tet T: 0 contactor, 1 target), clamped to [0, 1], of a
// pair that passed the face-plane test (`frame` as filled by prepare_tet_pair); returns the
// smallest.
inline double slab_depths(const TetPairFrame& frame, double (&mu)[8]) {
  // The four faces side by side (one vector lane each), with std::max's and std::clamp's choices.
  const auto larger = [](Lanes x, Lanes y) { return x < y ? y : x; };
  for (int T = 0; T < 2; ++T) {
    const double(&at_other_corners)[4][4] = frame.lambda_other[1 - T];
    const Lanes peak =
        larger(larger(load_lanes(at_other_corners[0]), load_lanes(at_other_corners[1])),
               larger(load_lanes(at_other_corners[2]), load_lanes(at_other_corners[3])));
    const Lanes zero = splat(0.0), one = splat(1.0);
    store_lanes(peak < zero ? zero : (one < peak ? one : peak), mu + 4 * T);
  }
  double thinnest = 1.0;
  for (int k = 0; k < 8; ++k) thinnest = std::min(thinnest, mu[k]);
  return thinnest;
}

// The slab depths narrowed by caps (into `reach`): Omega also lies in T ∩ {lambda_b^O >= 0} for
// each face b of the other tet O, the cap of T beyond that face's plane.  On the cap lambda_a^T
// peaks at a vertex: corner a itself when it lies beyond the plane (lambda_a^T = 1 there), else a
// point where an edge from a corner v beyond the plane to corner a crosses it, where
// lambda_a^T = l_v / (l_v - l_a) (l = lambda_b^O at the corners), largest for the largest l_v,
// which is mu_b^O.  This is what makes a small tet's slabs thin when it presses on a larger one:
// the larger tet's corners lie far out in every slab of the smaller (its mu near 1), though the
// overlap is a sheet along the larger tet's face.  Only the faces T pokes through thinly
// (mu_b^O < kPrismSlab) are tried: elsewhere the cap is most of T.
// True when some depth was narrowed.
inline bool narrow_slab_depths(const TetPairFrame& frame, const double (&mu)[8],
                               double (&reach)[8]) {
  bool narrowed = false;
  for (int k = 0; k < 8; ++k) reach[k] = mu[k];
  for (int T = 0; T < 2; ++T) {
    const int other = 1 - T;
    const double(&at_corner)[4][4] = frame.lambda_other[T];  // [corner v of T][face b of other]
    for (int b = 0; b < 4; ++b) {
      if (!(mu[4 * other + b] < kPrismSlab)) continue;
      double beyond = 0.0;  // the largest lambda_b^O at a corner of T: mu_b^O unclamped
      for (int v = 0; v < 4; ++v) beyond = std::max(beyond, at_corner[v][b]);
      for (int a = 0; a < 4; ++a)
        if (at_corner[a][b] < 0.0) {
          const double cap = beyond / (beyond - at_corner[a][b]);
          narrowed = narrowed || cap < reach[4 * T + a];
          reach[4 * T + a] = std::min(reach[4 * T + a], cap);
        }
    }
  }
  return narrowed;
}

// The two tets' gradient metrics ([0] contactor, [1] target), from the tets or from `frame`.
struct PairMetrics {
  const GradientMetrics* of[2];
};
struct FrameMetrics {
  GradientMetrics metrics[2];
  explicit FrameMetrics(const TetPairFrame& frame) {
    for (int T = 0; T < 2; ++T)
      gradient_metrics(frame.map[T].gradient, frame.map[T].edge_det, frame.local[T], metrics[T]);
  }
  PairMetrics pair() const { return PairMetrics{{&metrics[0], &metrics[1]}}; }
};

// The bound from the slab depths of slab_depths (or narrowed by narrow_slab_depths); penalty in
// Pa; `metrics` of frame's gradients.  With `enough_share` >= 0 it returns as soon as its nodal
// force is at most enough_share · length² (then only nodal_force and length hold): each
// further prism only lowers it, so whether the whole bound is that low is decided alike, for less.
inline PairForceBound pair_force_bound(const TetPairFrame& frame, const PairMetrics& metrics,
                                       const double (&mu)[8], double penalty,
                                       double enough_share = -1.0) {
  const Vec3* gradient[8];
  double potential_bound[2], gradient_max[2], volume[2];
  int thin[8] = {}, thin_count = 0;  // slabs thin enough for their prisms to matter
  double slab_norm[8];               // |g| of slab k
  for (int T = 0; T < 2; ++T) {
    double smallest_mu = 1.0;
    for (int a = 0; a < 4; ++a) {
      const int k = 4 * T + a;
      smallest_mu = std::min(smallest_mu, mu[k]);
      gradient[k] = &frame.map[T].gradient[a];
      slab_norm[k] = metrics.of[T]->norm[a];
      thin[thin_count] = k;  // kept where thin (no branch: which slabs are thin varies by pair)
      thin_count += mu[k] < kPrismSlab;
    }
    potential_bound[T] = 4.0 * smallest_mu;
    gradient_max[T] = metrics.of[T]->largest;
    volume[T] = metrics.of[T]->volume;
  }
  // The thinnest slabs first, and the prisms and parallelepipeds of the kMaxThinSlabs thinnest
  // only (their number grows as the cube of the slabs'; any of them bounds, so fewer leave the
  // bound rigorous).
  // Insertion sort (at most 8, stable), its first step without a branch: most pairs have two thin
  // slabs (a pressed face: one per tet) in either order.
  const bool swap_first = thin_count >= 2 && mu[thin[1]] < mu[thin[0]];
  const int first = thin[0], second = thin[1];
  thin[0] = swap_first ? second : first;
  thin[1] = swap_first ? first : second;
  for (int i = 2; i < thin_count; ++i)
    for (int j = i; j > 0 && mu[thin[j]] < mu[thin[j - 1]]; --j) std::swap(thin[j], thin[j - 1]);
  thin_count = std::min(thin_count, kMaxThinSlabs);
  PairForceBound bound;
  bound.length = std::min(metrics.of[0]->longest_edge, metrics.of[1]->longest_edge);
  const double length = bound.length;

  // Whole tets: face a's area is 3V |grad lambda_a| <= 3V G_T.
  double volume_bound = std::min(volume[0], volume[1]);
  double surface_bound = 12.0 * std::min(volume[0] * gradient_max[0], volume[1] * gradient_max[1]);
  // One slab alone: the part of T within lambda_a <= mu is at most 3 mu of T's volume.
  for (int k = 0; k < 8; ++k) volume_bound = std::min(volume_bound, 3.0 * mu[k] * volume[k / 4]);
  const auto nodal_force = [&] {
    return penalty *
           std::max(4.0 * gradient_max[0] * volume_bound + potential_bound[1] * surface_bound,
                    4.0 * gradient_max[1] * volume_bound + potential_bound[0] * surface_bound);
  };
  const double enough = enough_share * length * length;
  const auto early = [&] {  // (a whole bound is asked for: its force once, at the end)
    if (!(enough_share >= 0.0)) return false;
    bound.nodal_force = nodal_force();
    return bound.nodal_force <= enough;
  };
  if (early()) return bound;
  double norm[kMaxThinSlabs];  // (all four: a loop to thin_count is a branch that varies)
  for (int i = 0; i < kMaxThinSlabs; ++i) norm[i] = slab_norm[thin[i]];
  Vec3 cross[8][8];  // [i][j], i < j: g_thin[i] × g_thin[j]
  for (int i = 0; i < thin_count; ++i)
    for (int j = i + 1; j < thin_count; ++j) {
      const int k = thin[i], l = thin[j];
      cross[i][j] = gradient[k]->cross(*gradient[l]);
      // (within one tet the tet's own: the norm of g_l × g_k = −(g_k × g_l) is the same)
      const double cross_norm = k / 4 == l / 4
                                    ? metrics.of[k / 4]->cross_norm[kFacePair[k % 4][l % 4]]
                                    : cross[i][j].norm();
      if (!(cross_norm > 0.0)) continue;
      const double section = mu[k] * mu[l] / cross_norm;
      const double perimeter = 2.0 * (mu[k] * norm[j] + mu[l] * norm[i]) / cross_norm;
      volume_bound = std::min(volume_bound, section * length);
      surface_bound = std::min(surface_bound, 2.0 * section + perimeter * length);
      if (early()) return bound;
    }
  // Three slabs: a parallelepiped, thin in all three directions where a corner pokes into the
  // other tet (the prism above stays a whole edge long there).  Its edges are mu_k times the dual
  // vectors of the three gradients, so volume mu_k mu_l mu_m / |det| and faces mu_l mu_m |g_k| /
  // |det|, det = g_k · (g_l × g_m).
  for (int i = 0; i < thin_count; ++i)
    for (int j = i + 1; j < thin_count; ++j)
      for (int m = j + 1; m < thin_count; ++m) {
        const int k = thin[i], l = thin[j], n = thin[m];
        const double det = std::abs(gradient[n]->dot(cross[i][j]));
        if (!(det > 0.0)) continue;
        volume_bound = std::min(volume_bound, mu[k] * mu[l] * mu[n] / det);
        surface_bound = std::min(
            surface_bound,
            2.0 * (mu[l] * mu[n] * norm[i] + mu[k] * mu[n] * norm[j] + mu[k] * mu[l] * norm[m]) /
                det);
        if (early()) return bound;
      }
  bound.volume = volume_bound;
  bound.surface = surface_bound;
  bound.nodal_force = nodal_force();
  bound.energy = penalty * volume_bound *
                 (std::min(1.0, potential_bound[0]) + std::min(1.0, potential_bound[1]));
  return bound;
}

// `frame` as filled by prepare_tet_pair (the pair passed the face-plane test); penalty in Pa.  The
// slab depths narrowed by caps.
inline PairForceBound pair_force_bound(const TetPairFrame& frame, double penalty) {
  double mu[8], reach[8];
  slab_depths(frame, mu);
  narrow_slab_depths(frame, mu, reach);
  const FrameMetrics metrics(frame);
  return pair_force_bound(frame, metrics.pair(), reach, penalty);
}

// Per piece of a pair (sub-tet i of tet T clipped by the other tet: index 4T + i), an upper bound
// (N / Pa) of what it contributes to any nodal force.  On piece (T, i) the own coordinate
// lambda_i^T is the smallest of tet T's, so it is below every mu_a^T: the piece lies in the slab
// of face i thinned to m_T = min_a mu_a^T besides the pair's slabs, and beside a pressed face F
// the pieces of the sub-tets next to F lie in the prism of the slabs i and F, both m_T thin.
// Leaving the piece out removes its volume term on T's nodes (<= 4 G_T V) and its surface terms on
// the other tet's nodes (<= Phi_T S, Phi_T = 4 m_T), and hands its kept neighbours the boundary
// term it cancelled (<= Phi_T S on T's nodes; potential_contact.cpp adds it, so the forces stay
// the gradient of the kept energy).  A tet whose every piece is sure to exceed `above` (or that
// has no slab thinner than kPrismSlab) gets infinity, uncomputed.
// Only the tets in `tets` (bit T) are bounded; the others' pieces get infinity.
inline void piece_force_bounds(const PairMetrics& metrics, const double (&mu)[8],
                               const PairForceBound& pair, double above, double (&bound)[8],
                               unsigned tets = 3u) {
  for (int T = 0; T < 2; ++T) {
    for (int i = 0; i < 4; ++i) bound[4 * T + i] = std::numeric_limits<double>::infinity();
    if (!((tets >> T) & 1u)) continue;
    const double* own = mu + 4 * T;
    const double thinnest_own = std::min(std::min(own[0], own[1]), std::min(own[2], own[3]));
    if (!(thinnest_own < kPrismSlab)) continue;
    const GradientMetrics& tet = *metrics.of[T];
    const double(&norm)[4] = tet.norm;
    const double largest = tet.largest;
    // Every section below is at least m_T² / G_T² (|g_a × g_b| <= G_T²).
    const double least_volume =
        std::min(pair.volume, thinnest_own * thinnest_own * pair.length / (largest * largest));
    if (!(4.0 * largest * least_volume <= above)) continue;
    // The prism of slabs a, b for piece i: its slab of face i thinned to m_T.  The four pieces
    // side by side (one vector lane each, each lane rounding as alone).
    const double length = pair.length;
    Lanes volume = splat(pair.volume), surface = splat(pair.surface);
    const Lanes thinned = splat(thinnest_own);
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        if (!(tet.cross_norm[kFacePair[a][b]] > 0.0)) continue;
        const double inverse_cross = tet.inverse_cross_norm[kFacePair[a][b]];
        // Lane i: face i's thinned (lane_index(): a blend, where a lane written at a variable
        // index went through memory).
        const Lanes nu_a = select(lane_index() == a, thinned, splat(own[a]));
        const Lanes nu_b = select(lane_index() == b, thinned, splat(own[b]));
        const Lanes section = nu_a * nu_b * inverse_cross;
        const Lanes perimeter = 2.0 * (nu_a * norm[b] + nu_b * norm[a]) * inverse_cross;
        const Lanes prism_volume = section * length;
        const Lanes prism_surface = 2.0 * section + perimeter * length;
        volume = prism_volume < volume ? prism_volume : volume;  // std::min(volume, ...)
        surface = prism_surface < surface ? prism_surface : surface;
      }
    store_lanes(4.0 * largest * volume + 4.0 * thinnest_own * surface, bound + 4 * T);
  }
}

// Which parts of a pair may be left out: every piece (kEveryPiece) when the whole pair is proven
// to exert no nodal force above tolerance · p · ℓ² (ℓ the shorter tet's longest edge; p ℓ² is
// about the force of a full overlap), nor above kPressedFaceShare of mu · p · ℓ², about what a
// face pressed as deep (mu the thinnest slab) carries; otherwise the pieces proven below the same
// limit (piece_force_bounds).  The second condition keeps every pressed face in contact from its
// first touch, so no face contact starts with a jump of its energy: only the pairs and pieces
// whose forces grow faster than their depth (slivers beside a pressed face, edges and corners)
// wait until they matter.  Only a pair with a slab thinner than kThinSlab can pass, so the bound
// is computed only there: a deep overlap pays one scan of its 32 corner coordinates.
constexpr double kPressedFaceShare = 1e-3;
constexpr unsigned kEveryPiece = 0xFFu;

inline unsigned negligible_parts(const TetPairFrame& frame, const PairMetrics& metrics,
                                 double tolerance, bool kept_before = false) {
  constexpr double kThinSlab = 1e-3;
  double mu[8];
  const double thinnest = slab_depths(frame, mu);  // the depth of the pressure: sets the limit
  if (!(thinnest < kThinSlab)) return 0;
  const double share = std::min(tolerance, kPressedFaceShare * thinnest);
  // The pair as a whole is tried on its slab depths, its pieces on the depths narrowed by the caps.
  // (Whole pairs skipped on the narrowed depths cost a block sliding over shifted meshes 2 % of
  // its friction work against mu·N·s; leaving their pieces out instead does not.)
  double reach[8], piece[8];
  bool narrowed = false;
  // With at most two slabs under kPrismSlab on the narrowed depths (a pressed face: one per tet),
  // the bound on them has every term of the bound on the slab depths (thin there means thin
  // here), each from no larger depths, with the same roundings: above the limit, it proves the
  // pair's own bound above it too, which then need not be computed.  Tried first for a pair that
  // kept pieces at the step before (`kept_before`: a hint, the decisions are the same without);
  // most others are left out whole on the slab depths alone.
  PairForceBound caps;
  bool caps_known = false, pair_bound_above = false;
  double limit = 0.0;
  if (kept_before) {
    narrowed = narrow_slab_depths(frame, mu, reach);
    int thin_narrowed = 0;
    for (int k = 0; k < 8; ++k) thin_narrowed += reach[k] < kPrismSlab;
    if (narrowed && thin_narrowed <= 2) {
      caps = pair_force_bound(frame, metrics, reach, 1.0);
      caps_known = true;
      limit = share * caps.length * caps.length;
      pair_bound_above = caps.nodal_force > limit;
    }
  }
  if (!pair_bound_above) {
    const PairForceBound bound = pair_force_bound(frame, metrics, mu, 1.0, share);
    limit = share * bound.length * bound.length;
    if (bound.nodal_force <= limit) return kEveryPiece;  // (else the bound is whole)
    if (!kept_before) narrowed = narrow_slab_depths(frame, mu, reach);
    if (!caps_known) caps = narrowed ? pair_force_bound(frame, metrics, reach, 1.0) : bound;
  }
  const double(&depth)[8] = narrowed ? reach : mu;
  // A tet whose pieces are all below the limit on the pair's caps alone: each piece's bound is
  // the same sum of the same products of numbers no larger (rounding keeps the order), so the
  // same pieces are left out without their prisms.  (In the dry-stone wall every pair all of
  // whose pieces are left out is decided so.)
  unsigned skipped = 0, tets = 0;
  for (int T = 0; T < 2; ++T) {
    const double* own = depth + 4 * T;
    const double thinnest_own = std::min(std::min(own[0], own[1]), std::min(own[2], own[3]));
    const double largest = metrics.of[T]->largest;
    if (thinnest_own < kPrismSlab &&
        4.0 * largest * caps.volume + 4.0 * thinnest_own * caps.surface <= limit)
      skipped |= 0xFu << (4 * T);
    else
      tets |= 1u << T;
  }
  if (tets == 0) return skipped;
  piece_force_bounds(metrics, depth, caps, limit, piece, tets);
  for (int k = 0; k < 8; ++k) skipped |= piece[k] <= limit ? 1u << k : 0u;
  return skipped;
}

// The same with the metrics computed from `frame` (a single pair).
inline unsigned negligible_parts(const TetPairFrame& frame, double tolerance,
                                 bool kept_before = false) {
  const FrameMetrics metrics(frame);
  return negligible_parts(frame, metrics.pair(), tolerance, kept_before);
}

}  // namespace fdem
