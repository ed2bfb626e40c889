// Cheap geometric tests for a pair of tetrahedra, shared by the contact kernel and the broad
// phase: barycentric maps, axis-aligned boxes and separating planes.
//
// The face-plane test works on barycentric coordinates: tet B lies outside face a of tet A when
// every corner of B has lambda^A_a < 0.  The exact contact kernel clips with the very same
// values, so a pair this test rejects can never be found overlapping by the kernel.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/lanes.hpp"
#include "core/types.hpp"

namespace fdem {

// Node positions of one tetrahedron (m).  Either orientation is accepted.
struct TetCorners {
  Vec3 x[4];
};

// Barycentric coordinates of one tet as affine functions of the local position y = x - origin:
// lambda_a(y) = gradient[a] . y + offset[a].  lambda_a vanishes on the face opposite node a.
struct BarycentricMap {
  Vec3 gradient[4];  // 1/m
  double offset[4];  // -
  double edge_det;   // det[x1-x0, x2-x0, x3-x0] = 6 * signed volume (m^3)
  double value(int a, const Vec3& y) const { return gradient[a].dot(y) + offset[a]; }
};

// The origin-free part of the map: gradients and edge determinant; false for a degenerate (flat
// or non-finite) tet, which has no interior.
inline bool barycentric_gradients(const TetCorners& tet, Vec3 (&gradient)[4], double& edge_det) {
  const Vec3 e1 = tet.x[1] - tet.x[0];
  const Vec3 e2 = tet.x[2] - tet.x[0];
  const Vec3 e3 = tet.x[3] - tet.x[0];
  const Vec3 c1 = e2.cross(e3);
  const Vec3 c2 = e3.cross(e1);
  const Vec3 c3 = e1.cross(e2);
  const double det = e1.dot(c1);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  gradient[1] = c1 * inv;
  gradient[2] = c2 * inv;
  gradient[3] = c3 * inv;
  gradient[0] = -(gradient[1] + gradient[2] + gradient[3]);
  edge_det = det;
  return true;
}

// The barycentric coordinates at `point` of a tet with these gradients and corner 0 (`corner0`);
// false when not finite.
inline bool barycentric_values(const Vec3 (&gradient)[4], const Vec3& corner0, const Vec3& point,
                               double (&value)[4]) {
  const Vec3 y0 = corner0 - point;
  value[1] = -gradient[1].dot(y0);
  value[2] = -gradient[2].dot(y0);
  value[3] = -gradient[3].dot(y0);
  value[0] = 1.0 - value[1] - value[2] - value[3];
  return std::isfinite(value[0]);
}

// The offsets for the local origin `origin` (the coordinates there); false when not finite.
inline bool barycentric_offsets(const Vec3& corner0, const Vec3& origin, BarycentricMap& map) {
  return barycentric_values(map.gradient, corner0, origin, map.offset);
}

// Builds the map; false for a degenerate (flat or non-finite) tet, which has no interior.
inline bool make_barycentric_map(const TetCorners& tet, const Vec3& origin, BarycentricMap& map) {
  return barycentric_gradients(tet, map.gradient, map.edge_det) &&
         barycentric_offsets(tet.x[0], origin, map);
}

inline Vec3 tet_centroid(const TetCorners& tet) {
  return 0.25 * (tet.x[0] + tet.x[1] + tet.x[2] + tet.x[3]);
}

// Axis-aligned box of a tet's corners (m).
struct TetBox {
  double lo[3], hi[3];
};

inline TetBox tet_box(const TetCorners& t) {
  TetBox box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = std::min(std::min(t.x[0][k], t.x[1][k]), std::min(t.x[2][k], t.x[3][k]));
    box.hi[k] = std::max(std::max(t.x[0][k], t.x[1][k]), std::max(t.x[2][k], t.x[3][k]));
  }
  return box;
}

// True when the boxes intersect (touching counts as intersecting).  Bitwise, not short-circuit:
// which comparison decides is data-dependent, and one branch on the result mispredicts less.
inline bool boxes_intersect(const TetBox& a, const TetBox& b) {
  bool apart = false;
  for (int k = 0; k < 3; ++k) apart |= (a.hi[k] < b.lo[k]) | (b.hi[k] < a.lo[k]);
  return !apart;
}

inline bool tet_boxes_intersect(const TetCorners& a, const TetCorners& b) {
  return boxes_intersect(tet_box(a), tet_box(b));
}

// lambda[v][a]: barycentric coordinate a of `map`'s tet at corner v of `other` (local coords).
// The four coordinates side by side (one vector lane each), each summed as value() sums it:
// (g_x y_x + g_y y_y) + g_z y_z, then the offset.
inline void barycentric_at_corners(const BarycentricMap& map, const Vec3 (&other_local)[4],
                                   double (&lambda)[4][4]) {
  const Vec3(&g)[4] = map.gradient;
  const Lanes gx = {g[0].x(), g[1].x(), g[2].x(), g[3].x()};
  const Lanes gy = {g[0].y(), g[1].y(), g[2].y(), g[3].y()};
  const Lanes gz = {g[0].z(), g[1].z(), g[2].z(), g[3].z()};
  const Lanes offset = load_lanes(map.offset);
  for (int v = 0; v < 4; ++v) {
    const Vec3& y = other_local[v];
    store_lanes(gx * y.x() + gy * y.y() + gz * y.z() + offset, lambda[v]);
  }
}

// True when all four corners of the other tet lie strictly outside face a of the map's tet
// (lambda_a < 0 at every corner).  Bitwise, as boxes_intersect.
inline bool outside_face_plane(const double (&lambda)[4][4], int a) {
  return (lambda[0][a] < 0.0) & (lambda[1][a] < 0.0) & (lambda[2][a] < 0.0) & (lambda[3][a] < 0.0);
}

// True when some face plane of the map's tet has all four corners of the other tet strictly
// outside.  Bitwise, as boxes_intersect.
inline bool separated_by_face_plane(const double (&lambda)[4][4]) {
  // The four planes side by side (one vector lane each): the comparisons outside_face_plane makes.
  const LaneMask outside = (load_lanes(lambda[0]) < 0.0) & (load_lanes(lambda[1]) < 0.0) &
                           (load_lanes(lambda[2]) < 0.0) & (load_lanes(lambda[3]) < 0.0);
  return (outside[0] | outside[1] | outside[2] | outside[3]) != 0;
}

// The interval [lo, hi] that the four corners project to on `axis`.
struct ProjectedExtent {
  double lo, hi;
};
inline ProjectedExtent projected_extent(const Vec3& axis, const Vec3 (&corners)[4]) {
  ProjectedExtent e{axis.dot(corners[0]), axis.dot(corners[0])};
  for (int v = 1; v < 4; ++v) {
    const double p = axis.dot(corners[v]);
    e.lo = std::min(e.lo, p);
    e.hi = std::max(e.hi, p);
  }
  return e;
}

// A tet's six edges, as pairs of its corners.
constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

// The edge–edge axis (6 × edge of a + edge of b, 0..35: the cross product of the two edges) along
// which the two tets (corners in one frame) lie apart by a gap above `relative_margin` of their
// two extents along it (0: any gap; parallel edges give no axis), or -1.  Axis `first` (0..35),
// e.g. the one that separated them at the step before, is tried first.  The face normals are
// separated_by_face_plane's: exact SAT for convex polyhedra needs both sets.
inline int separating_edge_axis(const Vec3 (&a)[4], const Vec3 (&b)[4], double relative_margin,
                                int first = -1, double* gap = nullptr) {
  const auto separates = [&](int axis_index) {
    const int* ea = kTetEdges[axis_index / 6];
    const int* eb = kTetEdges[axis_index % 6];
    const Vec3 axis = (a[ea[1]] - a[ea[0]]).cross(b[eb[1]] - b[eb[0]]);
    const ProjectedExtent on_a = projected_extent(axis, a), on_b = projected_extent(axis, b);
    const double margin = relative_margin * ((on_a.hi - on_a.lo) + (on_b.hi - on_b.lo));
    const double separation = std::max(on_b.lo - on_a.hi, on_a.lo - on_b.hi);
    if (!(separation > margin)) return false;
    if (gap) *gap = (separation - margin) / axis.norm();  // m, the margin left out
    return true;
  };
  if (first >= 0 && first < 36 && separates(first)) return first;
  for (int axis_index = 0; axis_index < 36; ++axis_index)
    if (axis_index != first && separates(axis_index)) return axis_index;
  return -1;
}

// Whether an edge–edge axis separates the two tets (any gap), about the first tet's corner 0.
inline bool separated_by_edge_axis(const TetCorners& a, const TetCorners& b) {
  Vec3 pa[4], pb[4];
  for (int v = 0; v < 4; ++v) {
    pa[v] = a.x[v] - a.x[0];
    pb[v] = b.x[v] - a.x[0];
  }
  return separating_edge_axis(pa, pb, 0.0) >= 0;
}

// The edge–edge axis that separates the two tets by a gap above 1e-9 of their extents, or -1.
// That gap is far above the round-off of the exact kernel's clip, which therefore finds no
// overlap either: skipping such a pair changes no result.  `gap` (optional) gets the gap beyond
// that margin (m).
inline int clearly_separating_edge_axis(const Vec3 (&a)[4], const Vec3 (&b)[4], int first = -1,
                                        double* gap = nullptr) {
  return separating_edge_axis(a, b, 1e-9, first, gap);
}

// Everything the exact kernel needs about a pair once it has passed the cheap rejection.
struct TetPairFrame {
  Vec3 origin;                   // local origin = centroid of the contactor (m)
  Vec3 local[2][4];              // corner positions relative to origin; [0] contactor, [1] target
  BarycentricMap map[2];         // [0] contactor, [1] target
  double lambda_other[2][4][4];  // [s][v][a]: lambda of tet 1-s, component a, at corner v of s
};

// The square of the longest of the six edges of the tet with corners x (m²).
inline double longest_edge_squared(const Vec3 (&x)[4]) {
  double longest = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (x[a] - x[b]).squaredNorm());
  return longest;
}

// The lengths the sliver bounds (pair_force_bound.hpp) take from a tet (its barycentric map and
// its longest edge): computed once per tet and step for all its pairs, with the arithmetic the
// bounds would use, so the same values bit for bit.
struct GradientMetrics {
  double norm[4];        // |grad lambda_a| (1/m): 1 / the height over face a
  double largest;        // max_a norm[a] (1/m)
  double cross_norm[6];  // |grad lambda_a x grad lambda_b| (1/m^2), a < b at kFacePair[a][b]
  double inverse_cross_norm[6];  // 1 / cross_norm (m^2), 0 where cross_norm is not > 0
  double volume;                 // |edge_det| / 6 (m^3)
  double longest_edge;           // m
};

// The slot of the gradients' pair {a, b}, a != b, in GradientMetrics (-1 on the diagonal).
constexpr int kFacePair[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};

// `corners`: the tet's corners in any frame (for the longest edge).
inline void gradient_metrics(const Vec3 (&gradient)[4], double edge_det, const Vec3 (&corners)[4],
                             GradientMetrics& out) {
  out.volume = std::abs(edge_det) / 6.0;
  out.longest_edge = std::sqrt(longest_edge_squared(corners));
  out.largest = 0.0;
  for (int a = 0; a < 4; ++a) out.largest = std::max(out.largest, out.norm[a] = gradient[a].norm());
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      const int k = kFacePair[a][b];
      out.cross_norm[k] = gradient[a].cross(gradient[b]).norm();
      out.inverse_cross_norm[k] = out.cross_norm[k] > 0.0 ? 1.0 / out.cross_norm[k] : 0.0;
    }
}

// What a tet brings to every pair it is in: its corners and the origin-free part of its
// barycentric map.  The contact stage computes it once per tet and step for all the tet's pairs
// (a surface tet of a dense pile is in ~14); pairs built from it equal those built from the
// corners, bit for bit.
struct TetGeometry {
  TetCorners corners;
  Vec3 gradient[4];  // of the barycentric coordinates (1/m)
  // Of face a, unit: gradient[a] / |gradient[a]|, where has_normals (the contact stage's tets,
  // whose normals serve all their pairs; a single pair computes them only if it overlaps).
  Vec3 inward_normal[4];
  GradientMetrics metrics;  // of `gradient`
  double edge_det = 0.0;    // m^3
  bool valid = false;       // false: degenerate (flat or non-finite), overlaps nothing
  bool has_normals = false;
};

inline void compute_tet_geometry(const TetCorners& corners, TetGeometry& out,
                                 bool with_normals = true) {
  out.corners = corners;
  out.valid = barycentric_gradients(corners, out.gradient, out.edge_det);
  if (!out.valid) {  // no map: zeros rather than whatever was there
    for (Vec3& g : out.gradient) g.setZero();
    out.edge_det = 0.0;
  }
  gradient_metrics(out.gradient, out.edge_det, corners.x, out.metrics);
  out.has_normals = with_normals;
  if (with_normals)  // gradient / |gradient|, as Eigen's normalized() (zero stays zero)
    for (int a = 0; a < 4; ++a)
      out.inward_normal[a] =
          out.metrics.norm[a] > 0.0 ? Vec3(out.gradient[a] / out.metrics.norm[a]) : out.gradient[a];
}

// The tet's map about `origin` (its gradients and the offsets for that origin): the map
// make_barycentric_map builds from the corners, bit for bit.  False for a degenerate tet.
inline bool barycentric_map_about(const TetGeometry& tet, const Vec3& origin, BarycentricMap& map) {
  std::copy_n(tet.gradient, 4, map.gradient);
  map.edge_det = tet.edge_det;
  return tet.valid && barycentric_offsets(tet.corners.x[0], origin, map);
}

// A contactor's share of its pairs' frames, prepared once for all its pairs (the contact stage
// visits the pairs in contactor order): its centroid (the frames' origin), corners about it and
// barycentric map about it.  A frame built with it is the one built from the corners, bit for bit.
struct PreparedContactor {
  Vec3 origin;    // the centroid (m)
  Vec3 local[4];  // corners - origin (m)
  BarycentricMap map{};
  Vec3 inward_normal[4];    // as TetGeometry's
  GradientMetrics metrics;  // as TetGeometry's
  bool has_normals = false;
  bool valid = false;  // false: degenerate, overlaps nothing
};

inline void prepare_contactor(const TetGeometry& contactor, PreparedContactor& out) {
  out.origin = tet_centroid(contactor.corners);
  for (int v = 0; v < 4; ++v) out.local[v] = contactor.corners.x[v] - out.origin;
  out.has_normals = contactor.has_normals;
  if (contactor.has_normals) std::copy_n(contactor.inward_normal, 4, out.inward_normal);
  out.metrics = contactor.metrics;
  out.valid = barycentric_map_about(contactor, out.origin, out.map);
}

inline void prepare_contactor(const TetCorners& contactor, PreparedContactor& out) {
  TetGeometry geometry;
  compute_tet_geometry(contactor, geometry, false);
  prepare_contactor(geometry, out);
}

// Lambda_a of tet T (0 contactor, 1 target) at the other tet's four corners, with the arithmetic
// prepare_tet_pair's frame uses (the same values, so the same decisions), before the frame is
// built: most pairs apart stay apart at the plane that separated them at the step before, and
// only these four values are needed to see it.  False where the target's offsets are not finite.
inline bool plane_values_at_other(const PreparedContactor& contactor, const TetGeometry& target,
                                  int T, int a, double (&value)[4]) {
  if (T == 0) {
    for (int v = 0; v < 4; ++v)
      value[v] = contactor.map.value(a, target.corners.x[v] - contactor.origin);
    return true;
  }
  BarycentricMap map;  // the target's offsets about the contactor's centroid, as the frame's
  std::copy_n(target.gradient, 4, map.gradient);
  if (!barycentric_offsets(target.corners.x[0], contactor.origin, map)) return false;
  for (int v = 0; v < 4; ++v) value[v] = map.value(a, contactor.local[v]);
  return true;
}

inline bool outside_first_plane(const PreparedContactor& contactor, const TetGeometry& target,
                                int T, int a) {
  double value[4];
  if (!plane_values_at_other(contactor, target, T, a, value)) return false;
  return (value[0] < 0.0) & (value[1] < 0.0) & (value[2] < 0.0) & (value[3] < 0.0);
}

// The distance (m) by which the other tet's corners lie outside face a of tet T, less 1e-9 (of
// the barycentric coordinate, far above its round-off); 0 where that leaves nothing.
inline double face_plane_gap(const PreparedContactor& contactor, const TetGeometry& target, int T,
                             int a) {
  constexpr double kMargin = 1e-9;
  double value[4];
  if (!plane_values_at_other(contactor, target, T, a, value)) return 0.0;
  const double peak = std::max(std::max(value[0], value[1]), std::max(value[2], value[3]));
  const Vec3& gradient = T == 0 ? contactor.map.gradient[a] : target.gradient[a];
  return peak < -kMargin ? (-peak - kMargin) / gradient.norm() : 0.0;
}

// A pair's frame from the corners alone: the origin (the contactor's centroid), the corners about
// it and both maps, without the corner values; false for a degenerate tet.
inline bool frame_maps_from_corners(const TetCorners& contactor, const TetCorners& target,
                                    TetPairFrame& frame) {
  frame.origin = tet_centroid(contactor);
  for (int v = 0; v < 4; ++v) {
    frame.local[0][v] = contactor.x[v] - frame.origin;
    frame.local[1][v] = target.x[v] - frame.origin;
  }
  return make_barycentric_map(contactor, frame.origin, frame.map[0]) &&
         make_barycentric_map(target, frame.origin, frame.map[1]);
}

// The 4+4 face planes (the caller has tested the boxes: a pair whose boxes are apart ends the same,
// only later).  False when the pair certainly does not overlap (or a tet is degenerate); true
// means "may overlap" and fills `frame`.
// Face planes are numbered 4T + a: face a of tet T (0 contactor, 1 target).  `first_plane`, e.g.
// the one that separated the pair at the step before, is tested first, with the same arithmetic
// as the full test (the same decision); `separating_plane`, where given, gets the plane that
// separated the pair (-1: none, or a degenerate tet).
inline bool prepare_tet_pair(const PreparedContactor& contactor, const TetGeometry& target,
                             TetPairFrame& frame, int first_plane = -1,
                             int* separating_plane = nullptr) {
  if (separating_plane) *separating_plane = -1;
  if (!contactor.valid || !target.valid) return false;
  if (first_plane >= 0 && first_plane < 8 &&
      outside_first_plane(contactor, target, first_plane / 4, first_plane % 4)) {
    if (separating_plane) *separating_plane = first_plane;
    return false;
  }
  frame.origin = contactor.origin;
  for (int v = 0; v < 4; ++v) {
    frame.local[0][v] = contactor.local[v];
    frame.local[1][v] = target.corners.x[v] - frame.origin;
  }
  frame.map[0] = contactor.map;
  if (!barycentric_map_about(target, frame.origin, frame.map[1])) return false;
  // The separating plane among those of tet T whose values at the other's corners are `lambda`.
  const auto separated = [&](const double(&lambda)[4][4], int T) {
    if (!separated_by_face_plane(lambda)) return false;
    if (separating_plane)
      for (int a = 0; a < 4 && *separating_plane < 0; ++a)
        if (outside_face_plane(lambda, a)) *separating_plane = 4 * T + a;
    return true;
  };
  barycentric_at_corners(frame.map[1], frame.local[0], frame.lambda_other[0]);
  if (separated(frame.lambda_other[0], 1)) return false;
  barycentric_at_corners(frame.map[0], frame.local[1], frame.lambda_other[1]);
  if (separated(frame.lambda_other[1], 0)) return false;
  return true;
}

inline bool prepare_tet_pair(const TetCorners& contactor, const TetCorners& target,
                             TetPairFrame& frame) {
  if (!tet_boxes_intersect(contactor, target)) return false;
  PreparedContactor prepared;
  prepare_contactor(contactor, prepared);
  TetGeometry geometry;
  compute_tet_geometry(target, geometry, false);
  return prepare_tet_pair(prepared, geometry, frame);
}

// Cheap conservative rejection: false only when the tets certainly do not overlap (boxes
// apart or a separating face plane).  Never false for a pair potential_contact finds
// overlapping.  Edge-edge axes are left out: the benchmark shows they cost more than the
// exact integrations they save (see bench_contact_pair).
inline bool tets_may_overlap(const TetCorners& a, const TetCorners& b) {
  TetPairFrame frame;
  return prepare_tet_pair(a, b, frame);
}

}  // namespace fdem
