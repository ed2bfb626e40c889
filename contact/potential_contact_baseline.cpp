// The previous implementation of the exact potential contact (one moment per carried value per
// fan triangle, pieces rejected only by the other tet's face planes), kept unchanged as the
// baseline that bench_contact_pair times the current kernel against and that the unit tests
// cross-check it with.  Same formulas: see potential_contact_kernels.hpp.
#include <cmath>

#include "contact/potential_contact_kernels.hpp"

namespace fdem {
namespace {

// A tet clipped by four planes has at most 12 vertices (simple polyhedron, <= 8 faces); the
// headroom covers degenerate (noisy) classifications, which can split a face in two.
constexpr int kMaxVertices = 48;

// Plane tags carried by every vertex (bit set = the vertex lies on that plane).
constexpr unsigned kOuterFaceBit = 1u;  // the sub-tet's base = a face of its own tet
// bits 1..4: the sub-tet's sides (planes through the own centroid)
constexpr unsigned kOtherFaceShift = 8;  // bits 8..11: faces 0..3 of the other tet
constexpr unsigned kOtherFaceBits = 0xFu << kOtherFaceShift;

struct PieceVertex {
  double lam[8];  // [0..3] barycentric coords in the own tet, [4..7] in the other tet
  int next[3];    // neighbours, ordered so the face walk runs counter-clockwise from outside
  unsigned planes;
};

struct Piece {
  int count = 0;
  PieceVertex v[kMaxVertices];
};

// Neighbours of a positively oriented tet (corners 0..3 at the origin and unit axes).  Walking
// "arrive from next[k], leave by next[k+1]" traverses each face counter-clockwise seen from
// outside.  In own-barycentric space every sub-tet is positively oriented (see build_piece).
constexpr int kTetNeighbours[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Keeps the part of the piece where lam[k] >= 0 (Powell & Abel's r3d clip on a degree-3 vertex
// graph).  New vertices get lam[k] = 0 exactly and the plane bit.  False when nothing is left.
bool clip_piece(Piece& piece, int k, unsigned plane_bit) {
  const int n = piece.count;
  double dist[kMaxVertices];
  bool outside[kMaxVertices];
  int n_outside = 0;
  for (int i = 0; i < n; ++i) {
    dist[i] = piece.v[i].lam[k];
    outside[i] = dist[i] < 0.0;
    n_outside += outside[i];
  }
  if (n_outside == 0) return true;
  if (n_outside == n) {
    piece.count = 0;
    return false;
  }
  // One new vertex on every edge from a kept vertex to a clipped one.  Always interpolate from
  // the kept end so that a shared edge gives the same point in every piece that holds it.
  int m = n;
  for (int vc = 0; vc < n; ++vc) {
    if (outside[vc]) continue;
    for (int e = 0; e < 3; ++e) {
      const int vn = piece.v[vc].next[e];
      if (!outside[vn]) continue;
      if (m == kMaxVertices) {  // unreachable for tet ∩ half-spaces; stay finite regardless
        piece.count = 0;
        return false;
      }
      PieceVertex& w = piece.v[m];
      const PieceVertex& a = piece.v[vc];
      const PieceVertex& b = piece.v[vn];
      const double t = dist[vc] / (dist[vc] - dist[vn]);  // in [0, 1): dist[vc] >= 0 > dist[vn]
      for (int c = 0; c < 8; ++c) w.lam[c] = a.lam[c] + t * (b.lam[c] - a.lam[c]);
      w.lam[k] = 0.0;
      w.planes = (a.planes & b.planes) | plane_bit;
      w.next[0] = vc;
      w.next[1] = -1;
      w.next[2] = -1;
      outside[m] = false;
      piece.v[vc].next[e] = m;
      ++m;
    }
  }
  // Close the cap: from each new vertex walk its face until the next new vertex.
  for (int vs = n; vs < m; ++vs) {
    int vc = vs;
    int vn = piece.v[vc].next[0];
    int guard = 0;
    do {
      int e = 0;
      while (e < 3 && piece.v[vn].next[e] != vc) ++e;
      if (e == 3 || ++guard > 3 * kMaxVertices) {  // corrupted graph: cannot happen
        piece.count = 0;
        return false;
      }
      vc = vn;
      vn = piece.v[vc].next[(e + 1) % 3];
    } while (vc < n);
    piece.v[vs].next[2] = vc;
    piece.v[vc].next[1] = vs;
  }
  // Drop the clipped vertices and renumber.
  int remap[kMaxVertices];
  int kept = 0;
  for (int i = 0; i < m; ++i) {
    if (outside[i]) continue;
    remap[i] = kept;
    if (kept != i) piece.v[kept] = piece.v[i];
    ++kept;
  }
  for (int i = 0; i < kept; ++i)
    for (int e = 0; e < 3; ++e) piece.v[i].next[e] = remap[piece.v[i].next[e]];
  piece.count = kept;
  return kept > 0;
}

// Integrals over the pieces of one side, in own-barycentric space (lambda_1..3 as coordinates;
// physical volume = |edge_det| * that volume).
struct SideIntegrals {
  double vol6[4] = {0, 0, 0, 0};  // per sub-tet i: 6 * volume in barycentric space
  double moment[4][8] = {};       // per sub-tet i: sum vol6_tet * (sum of its 4 vertex values)
  double surface[4][4] = {};  // [other face j][other node b]: ∫ 4 lambda_i^own lambda_b^other dS
                              // * 24 (physical area), over the pieces' faces on face j
};

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

ContactPairResult zero_result() {
  ContactPairResult r;
  for (int v = 0; v < 4; ++v) {
    r.force_contactor[v].setZero();
    r.force_target[v].setZero();
  }
  r.normal.setZero();
  r.centroid.setZero();
  return r;
}

ContactPairResult assemble(const TetPairFrame& frame, double penalty) {
  ContactPairResult r = zero_result();

  SideIntegrals side[2];
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
  double weight_c[4] = {0, 0, 0, 0}, weight_t[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i)
    for (int a = 0; a < 4; ++a) {
      weight_c[a] += vol_integral[0][i][a];
      weight_t[a] += vol_integral[0][i][4 + a];
    }
  // The overlap lies inside both tets, so its centroid's barycentric weights are in [0, 1] and
  // sum to 1.  For a round-off sliver (touching coplanar faces, overlap ~1e-50 m^3) the moment
  // ratios are noise (seen: weights ~3e14, a "centroid" 5e13 m away); clamping keeps the
  // velocity interpolation and the force spreading of friction and dashpot bounded.  Exact
  // overlaps are unchanged.
  const auto clamp_weights = [](const double(&raw)[4], double(&out)[4]) {
    double sum = 0.0;
    for (int a = 0; a < 4; ++a) sum += (out[a] = std::max(raw[a], 0.0));
    for (int a = 0; a < 4; ++a) out[a] = sum > 0.0 ? out[a] / sum : 0.25;
  };
  clamp_weights(weight_c, r.centroid_weights_contactor);
  clamp_weights(weight_t, r.centroid_weights_target);
  Vec3 centroid = Vec3::Zero();
  for (int a = 0; a < 4; ++a) centroid += r.centroid_weights_contactor[a] * frame.local[0][a];
  r.centroid = frame.origin + centroid;
  const Vec3 resultant =
      r.force_contactor[0] + r.force_contactor[1] + r.force_contactor[2] + r.force_contactor[3];
  r.normal_force = resultant.norm();
  if (r.normal_force > 0.0) r.normal = resultant / r.normal_force;
  return r;
}

}  // namespace

ContactPairResult potential_contact_baseline(const TetCorners& contactor, const TetCorners& target,
                                             double penalty) {
  TetPairFrame frame;
  if (!prepare_tet_pair(contactor, target, frame)) return zero_result();
  return assemble(frame, penalty);
}

}  // namespace fdem
