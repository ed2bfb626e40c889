// The previous implementation of the exact potential contact (one moment per carried value per
// fan triangle, pieces rejected only by the other tet's face planes), kept unchanged as the
// baseline that bench_contact_pair times the current kernel against and that the unit tests
// cross-check it with.  Same formulas: see potential_contact_kernels.hpp.
#include <cmath>

#include "contact/piece_clipper.hpp"
#include "contact/potential_contact_kernels.hpp"

namespace fdem {
namespace {

using namespace piece_clip;

// Accumulates one piece (sub-tet `own_sub` clipped): cone sums over all faces from an apex at the
// piece's first vertex (a point of the piece: no cancellation between remote cones, so slivers
// of overlap keep full relative precision), and the surface integrals on the faces that lie on
// the other tet's faces.
// area_weight[j]: maps a barycentric-space doubled area vector to the doubled physical area
// projected on face j's outward unit normal.
void integrate_piece(const Piece& piece, int own_sub, const Vec3 (&area_weight)[4],
                     SideIntegrals& out) {
  bool used[kMaxVertices][3] = {};
  const double* apex_values = piece.v[0].lam;  // apex: the first vertex of the piece
  const Vec3 apex(apex_values[1], apex_values[2], apex_values[3]);
  double piece_vol6 = 0.0;
  int face[kMaxVertices];
  for (int vs = 0; vs < piece.count; ++vs) {
    for (int es = 0; es < 3; ++es) {
      if (used[vs][es]) continue;
      // Walk one face.
      int nf = 0;
      unsigned face_planes = ~0u;
      int vc = vs, e = es;
      do {
        used[vc][e] = true;
        if (nf < kMaxVertices) face[nf++] = vc;
        face_planes &= piece.v[vc].planes;
        const int vn = piece.v[vc].next[e];
        int back = 0;
        while (back < 3 && piece.v[vn].next[back] != vc) ++back;
        if (back == 3) return;  // corrupted graph: cannot happen
        vc = vn;
        e = (back + 1) % 3;
      } while (vc != vs && nf < kMaxVertices);
      if (nf < 3) continue;
      const bool on_other = (face_planes & kOtherFaceBits) != 0;
      int other_face = -1;
      if (on_other) {
        const unsigned bits = (face_planes & kOtherFaceBits) >> kOtherFaceShift;
        other_face = (bits & 1u) ? 0 : (bits & 2u) ? 1 : (bits & 4u) ? 2 : 3;
      }
      // Fan from the face's first vertex.
      const PieceVertex& p0 = piece.v[face[0]];
      const Vec3 x0(p0.lam[1], p0.lam[2], p0.lam[3]);
      const Vec3 h0 = x0 - apex;
      for (int k = 1; k + 1 < nf; ++k) {
        const PieceVertex& p1 = piece.v[face[k]];
        const PieceVertex& p2 = piece.v[face[k + 1]];
        const Vec3 area2 = (Vec3(p1.lam[1], p1.lam[2], p1.lam[3]) - x0)
                               .cross(Vec3(p2.lam[1], p2.lam[2], p2.lam[3]) - x0);
        const double vol6 = h0.dot(area2);
        piece_vol6 += vol6;
        for (int c = 0; c < 8; ++c)
          out.moment[own_sub][c] += vol6 * (p0.lam[c] + p1.lam[c] + p2.lam[c]);
        if (other_face >= 0) {
          // ∫_tri f g dS = A/12 (sum f_k g_k + (sum f)(sum g)), f = 4 lambda_own, g =
          // lambda_other_b.
          const double area_phys2 = area2.dot(area_weight[other_face]);
          const double f0 = 4.0 * p0.lam[own_sub], f1 = 4.0 * p1.lam[own_sub],
                       f2 = 4.0 * p2.lam[own_sub];
          const double fsum = f0 + f1 + f2;
          for (int b = 0; b < 4; ++b) {
            const double g0 = p0.lam[4 + b], g1 = p1.lam[4 + b], g2 = p2.lam[4 + b];
            out.surface[other_face][b] +=
                area_phys2 * (f0 * g0 + f1 * g1 + f2 * g2 + fsum * (g0 + g1 + g2));
          }
        }
      }
    }
  }
  out.vol6[own_sub] += piece_vol6;
  for (int c = 0; c < 8; ++c) out.moment[own_sub][c] += piece_vol6 * apex_values[c];
}

// Integrates the four pieces (sub-tet i of `own`) ∩ other.
void integrate_side(const TetPairFrame& frame, int own, SideIntegrals& out) {
  const BarycentricMap& own_map = frame.map[own];
  const BarycentricMap& other_map = frame.map[1 - own];
  const double(&other_at_corner)[4][4] = frame.lambda_other[own];
  // Other tet's barycentrics at the own centroid: the corner average (so that a corner set
  // outside a face plane keeps the centroid outside too, consistent with the rejection test).
  double other_at_centroid[4];
  for (int b = 0; b < 4; ++b)
    other_at_centroid[b] = 0.25 * (other_at_corner[0][b] + other_at_corner[1][b] +
                                   other_at_corner[2][b] + other_at_corner[3][b]);
  // Doubled area vector in own-barycentric space -> doubled physical area along the outward unit
  // normal n_j of the other tet's face j: Nanson, n dS = |det D| D^-T N dS_lambda (the absolute
  // value keeps "outward" outward for either orientation); rows of D^-1 are grad lambda_1..3.
  Vec3 area_weight[4];
  for (int j = 0; j < 4; ++j) {
    const Vec3 normal = -other_map.gradient[j].normalized();
    area_weight[j] = std::abs(own_map.edge_det) * Vec3(own_map.gradient[1].dot(normal),
                                                       own_map.gradient[2].dot(normal),
                                                       own_map.gradient[3].dot(normal));
  }
  Piece piece;
  for (int i = 0; i < 4; ++i) {
    // Sub-tet i = own corners k != i plus the centroid in slot i.  In lambda_1..3 coordinates
    // the own tet is the unit simplex (positive), and replacing corner i by the centroid keeps
    // the orientation, so kTetNeighbours applies unchanged.
    const double* slot_other[4];
    for (int s = 0; s < 4; ++s) slot_other[s] = (s == i) ? other_at_centroid : other_at_corner[s];
    // Quick rejection: the four vertices strictly outside one plane of the other tet.
    bool empty = false;
    for (int b = 0; b < 4 && !empty; ++b)
      empty = slot_other[0][b] < 0.0 && slot_other[1][b] < 0.0 && slot_other[2][b] < 0.0 &&
              slot_other[3][b] < 0.0;
    if (empty) continue;
    piece.count = 4;
    for (int s = 0; s < 4; ++s) {
      PieceVertex& v = piece.v[s];
      for (int a = 0; a < 4; ++a) v.lam[a] = (s == i) ? 0.25 : (a == s ? 1.0 : 0.0);
      for (int b = 0; b < 4; ++b) v.lam[4 + b] = slot_other[s][b];
      for (int e = 0; e < 3; ++e) v.next[e] = kTetNeighbours[s][e];
      // Slot s lies on the three faces opposite the other slots.  Face opposite slot i is the
      // base (own face i); face opposite slot k != i is a side through the centroid.
      unsigned planes = 0;
      for (int s2 = 0; s2 < 4; ++s2)
        if (s2 != s) planes |= (s2 == i) ? kOuterFaceBit : (1u << (1 + s2));
      v.planes = planes;
    }
    bool alive = true;
    for (int b = 0; b < 4 && alive; ++b)
      alive = clip_piece(piece, 4 + b, 1u << (kOtherFaceShift + b));
    if (alive) integrate_piece(piece, i, area_weight, out);
  }
}

ContactPairResult assemble(const TetPairFrame& frame, double penalty) {
  ContactPairResult r = zero_result();

  SideIntegrals side[2]{};
  integrate_side(frame, 0, side[0]);
  integrate_side(frame, 1, side[1]);

  // Physical volume integrals: ∫_{piece i} lam_c dV = |det| * moment / 24 (moment includes the
  // apex term vol6 * lam_c(apex)).
  double vol_integral[2][4][8];  // [side][sub-tet][carried value]
  double volume[2] = {0.0, 0.0};
  for (int s = 0; s < 2; ++s) {
    const double jac = std::abs(frame.map[s].edge_det);
    for (int i = 0; i < 4; ++i) {
      for (int c = 0; c < 8; ++c) vol_integral[s][i][c] = jac * side[s].moment[i][c] * (1.0 / 24.0);
      volume[s] += jac * side[s].vol6[i] * (1.0 / 6.0);
    }
  }
  if (!(volume[0] > 0.0)) return r;  // touching or apart: zero everywhere

  double energy = 0.0;
  Vec3* force[2] = {r.force_contactor, r.force_target};
  for (int s = 0; s < 2; ++s) {
    const BarycentricMap& own = frame.map[s];
    const SideIntegrals& other_side = side[1 - s];  // its surfaces lie on this tet's faces
    for (int i = 0; i < 4; ++i) energy += vol_integral[s][i][i];
    for (int a = 0; a < 4; ++a) {
      Vec3 f = Vec3::Zero();
      for (int i = 0; i < 4; ++i) {
        // volume term: grad phi = 4 grad lambda_i on sub-tet i
        f += (4.0 * vol_integral[s][i][a]) * own.gradient[i];
        // surface term on own face i: - ∫ phi_other lambda_a n dS, n = outward unit normal
        f += (other_side.surface[i][a] * (1.0 / 24.0)) * own.gradient[i].normalized();
      }
      force[s][a] = penalty * f;
    }
  }
  energy *= 4.0 * penalty;

  r.overlapping = true;
  r.energy = energy;
  r.overlap_volume = volume[0];
  finish_pair_result(frame, vol_integral, r);
  return r;
}

// The pair's frame as the start built it, scalar, from the corners alone: the shared
// prepare_tet_pair has since taken per-tet work for the bounds (gradient metrics, longest edges)
// and vector lanes, which would change what the baseline costs.  The same values bit for bit.
bool start_frame(const TetCorners& contactor, const TetCorners& target, TetPairFrame& frame) {
  if (!tet_boxes_intersect(contactor, target) || !frame_maps_from_corners(contactor, target, frame))
    return false;
  for (int T : {1, 0}) {  // the other tet's corners in tet T's map, then its planes
    double(&lambda)[4][4] = frame.lambda_other[1 - T];
    for (int v = 0; v < 4; ++v)
      for (int a : {1, 2, 3, 0}) lambda[v][a] = frame.map[T].value(a, frame.local[1 - T][v]);
    bool separated = false;
    for (int a = 0; a < 4; ++a) separated |= outside_face_plane(lambda, a);
    if (separated) return false;
  }
  return true;
}

}  // namespace

ContactPairResult potential_contact_baseline(const TetCorners& contactor, const TetCorners& target,
                                             double penalty) {
  TetPairFrame frame;
  if (!start_frame(contactor, target, frame)) return zero_result();
  return assemble(frame, penalty);
}

}  // namespace fdem
