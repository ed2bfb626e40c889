// Exact distance between two tetrahedra, for narrowing candidate pairs at detection.
//
// Two disjoint convex polyhedra are closest either between a corner of one and a face of the
// other (the closest point of a face may lie on its edge or corner) or between an edge of each,
// so their distance is the smallest of 2 × 16 point–triangle and 36 segment–segment distances.
// Whether they are disjoint at all is decided first by the separating-axis test (the 8 face
// normals and the 36 edge × edge directions are complete for two tetrahedra); intersecting tets
// are at distance 0.  Closest-point routines after Ericson, Real-Time Collision Detection
// (2005), §5.1.5 and §5.1.9.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/tet_overlap.hpp"
#include "core/types.hpp"

namespace fdem {

// Squared distance (m²) from p to the triangle (a, b, c), by the Voronoi region of p.
inline double point_triangle_distance_sq(const Vec3& p, const Vec3& a, const Vec3& b,
                                         const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.squaredNorm();  // corner a
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.squaredNorm();  // corner b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return (ap - (d1 / (d1 - d3)) * ab).squaredNorm();
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.squaredNorm();  // corner c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return (ap - (d2 / (d2 - d6)) * ac).squaredNorm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (bp - w * (c - b)).squaredNorm();  // edge bc
  }
  const double denominator = va + vb + vc;
  if (!(std::abs(denominator) > 0.0)) {  // flat triangle: its three edges
    const auto segment = [&](const Vec3& s, const Vec3& e) {
      const Vec3 d = e - s;
      const double l2 = d.squaredNorm();
      const double t = l2 > 0.0 ? std::clamp((p - s).dot(d) / l2, 0.0, 1.0) : 0.0;
      return (p - s - t * d).squaredNorm();
    };
    return std::min({segment(a, b), segment(b, c), segment(c, a)});
  }
  const double v = vb / denominator, w = vc / denominator;
  return (ap - v * ab - w * ac).squaredNorm();  // interior of the face
}

// Squared distance (m²) between the segments p1–q1 and p2–q2.
inline double segment_segment_distance_sq(const Vec3& p1, const Vec3& q1, const Vec3& p2,
                                          const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (!(a > 0.0) && !(e > 0.0)) return r.squaredNorm();
  if (!(a > 0.0)) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (!(e > 0.0)) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denominator = a * e - b * b;
      s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p1 + s * d1 - p2 - t * d2).squaredNorm();
}

namespace tet_distance_detail {
// Whether the projections of the two corner sets on `axis` are apart (a gap > 0).
inline bool separated_along(const Vec3& axis, const Vec3 (&a)[4], const Vec3 (&b)[4]) {
  if (!(axis.squaredNorm() > 0.0)) return false;
  const ProjectedExtent on_a = projected_extent(axis, a), on_b = projected_extent(axis, b);
  return on_a.hi < on_b.lo || on_b.hi < on_a.lo;
}
}  // namespace tet_distance_detail

// Whether some plane separates the two tetrahedra (touching counts as not separated).
inline bool tets_disjoint(const Vec3 (&a)[4], const Vec3 (&b)[4]) {
  using tet_distance_detail::separated_along;
  for (int k = 0; k < 4; ++k) {  // face normals (unnormalised: only the sign of the gap counts)
    const int i = (k + 1) % 4, j = (k + 2) % 4, l = (k + 3) % 4;
    if (separated_along((a[j] - a[i]).cross(a[l] - a[i]), a, b)) return true;
    if (separated_along((b[j] - b[i]).cross(b[l] - b[i]), a, b)) return true;
  }
  return separating_edge_axis(a, b, 0.0) >= 0;
}

// Distance (m) between the two tetrahedra: 0 when they intersect or touch.
inline double tet_distance(const Vec3 (&a)[4], const Vec3 (&b)[4]) {
  if (!tets_disjoint(a, b)) return 0.0;
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k) {  // corners against the faces opposite corner k
    const int i = (k + 1) % 4, j = (k + 2) % 4, l = (k + 3) % 4;
    for (int c = 0; c < 4; ++c) {
      nearest = std::min(nearest, point_triangle_distance_sq(a[c], b[i], b[j], b[l]));
      nearest = std::min(nearest, point_triangle_distance_sq(b[c], a[i], a[j], a[l]));
    }
  }
  for (const auto& ea : kTetEdges)
    for (const auto& eb : kTetEdges)
      nearest =
          std::min(nearest, segment_segment_distance_sq(a[ea[0]], a[ea[1]], b[eb[0]], b[eb[1]]));
  return std::sqrt(nearest);
}

// Whether the two tetrahedra are within `distance` (m) of each other: tet_distance(a, b) <=
// distance, decided with early exits for narrowing, where most pairs tested touch or nearly
// touch (tets across a crack, blocks resting on each other).  A corner pair, then a corner–face
// and an edge–edge pair within reach settle it (each is an upper bound on the distance); only
// when none is within reach must the separating-axis test tell disjoint tets (farther) from
// intersecting ones (distance 0, e.g. one inside the other).
inline bool tets_within(const Vec3 (&a)[4], const Vec3 (&b)[4], double distance) {
  const double reach_sq = distance * distance;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if ((a[i] - b[j]).squaredNorm() <= reach_sq) return true;
  for (int k = 0; k < 4; ++k) {
    const int i = (k + 1) % 4, j = (k + 2) % 4, l = (k + 3) % 4;
    for (int c = 0; c < 4; ++c)
      if (point_triangle_distance_sq(a[c], b[i], b[j], b[l]) <= reach_sq ||
          point_triangle_distance_sq(b[c], a[i], a[j], a[l]) <= reach_sq)
        return true;
  }
  for (const auto& ea : kTetEdges)
    for (const auto& eb : kTetEdges)
      if (segment_segment_distance_sq(a[ea[0]], a[ea[1]], b[eb[0]], b[eb[1]]) <= reach_sq)
        return true;
  return !tets_disjoint(a, b);
}

}  // namespace fdem
