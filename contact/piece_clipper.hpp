// The convex clipper both potential-contact implementations share (potential_contact.cpp and
// the baseline kept for the benchmarks): a sub-tet in its own tet's barycentric coordinates,
// clipped by the other tet's face planes on a degree-3 vertex graph.  Internal to contact/.
#pragma once

#include <algorithm>
#include <cstdint>

#include "contact/potential_contact_kernels.hpp"

namespace fdem::piece_clip {

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

// The new vertex on edge a–b where the plane lam[k] = 0 cuts it (dist_a = a.lam[k] >= 0 >
// dist_b = b.lam[k]): interpolated from the kept end a, so that a shared edge gives the same point
// in every piece that holds it.  One function for the clip and its replay (clip_replay.hpp): the
// same operations, bit for bit.  The replay makes the coordinates only (its faces and their
// planes come with the record); the clip tags the vertex's planes too (cut_edge).
inline void cut_edge_values(const PieceVertex& a, const PieceVertex& b, double dist_a,
                            double dist_b, int k, PieceVertex& w) {
  const double t = dist_a / (dist_a - dist_b);  // in [0, 1)
  for (int c = 0; c < 8; ++c) w.lam[c] = a.lam[c] + t * (b.lam[c] - a.lam[c]);
  w.lam[k] = 0.0;
}
inline void cut_edge(const PieceVertex& a, const PieceVertex& b, double dist_a, double dist_b,
                     int k, unsigned plane_bit, PieceVertex& w) {
  cut_edge_values(a, b, dist_a, dist_b, k, w);
  w.planes = (a.planes & b.planes) | plane_bit;
}

// What one clip did, for its replay at the next step (clip_replay.hpp): per plane, which
// vertices lay outside and which edges were cut, in the order the clipper made the new vertices.
// `valid` turns false where the record would not fit (or the graph was corrupted).
struct ClipLog {
  static constexpr int kMaxBytes = 255;
  static constexpr int kMaxStageVertices = 16;  // the outside mask is 16 bits
  std::uint8_t bytes[kMaxBytes];
  int size = 0;
  int made = 4;  // vertices made so far, the sub-tet's four included: the replay's pool size
  bool valid = true;
  bool room(int count) {
    valid = valid && size + count <= kMaxBytes;
    return valid;
  }
  void put(unsigned value) { bytes[size++] = static_cast<std::uint8_t>(value); }
};

// Keeps the part of the piece where lam[k] >= 0 (Powell & Abel's r3d clip on a degree-3 vertex
// graph).  New vertices get lam[k] = 0 exactly and the plane bit.  False when nothing is left.
// With a log, what it did is appended there.
inline bool clip_piece(Piece& piece, int k, unsigned plane_bit, ClipLog* log = nullptr) {
  const int n = piece.count;
  double dist[kMaxVertices];
  bool outside[kMaxVertices];
  int n_outside = 0;
  for (int i = 0; i < n; ++i) {
    dist[i] = piece.v[i].lam[k];
    outside[i] = dist[i] < 0.0;
    n_outside += outside[i];
  }
  if (log && (n > ClipLog::kMaxStageVertices || !log->room(3))) log->valid = false;
  if (log && log->valid) {
    unsigned mask = 0;
    for (int i = 0; i < n; ++i) mask |= static_cast<unsigned>(outside[i]) << i;
    log->put(mask & 0xFFu);
    log->put(mask >> 8);
  }
  if (n_outside == 0) return true;
  if (n_outside == n) {
    piece.count = 0;
    return false;
  }
  int count_at = -1;  // where the log keeps the number of new vertices
  if (log && log->valid) {
    count_at = log->size;
    log->put(0);
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
        if (log) log->valid = false;
        piece.count = 0;
        return false;
      }
      PieceVertex& w = piece.v[m];
      cut_edge(piece.v[vc], piece.v[vn], dist[vc], dist[vn], k, plane_bit, w);
      if (log && log->valid && log->room(2) && ++log->made <= kMaxVertices) {
        log->put(static_cast<unsigned>(vc));
        log->put(static_cast<unsigned>(vn));
        ++log->bytes[count_at];
      } else if (log) {
        log->valid = false;
      }
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
        if (log) log->valid = false;
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
// Value-initialise it (`SideIntegrals s{}`) to start from zero everywhere; potential_contact.cpp
// writes a row on first use instead and keeps which in `integrated` and `surfaced`.
struct SideIntegrals {
  double vol6[4];        // per sub-tet i: 6 * volume in barycentric space
  double moment[4][8];   // per sub-tet i: sum vol6_tet * (sum of its 4 vertex values)
  double surface[4][4];  // [other face j][other node b]: ∫ 4 lambda_i^own lambda_b^other dS
                         // * 24 (physical area), over the pieces' faces on face j
  // bit i: piece i was clipped to a non-empty polyhedron and integrated: vol6[i], moment[i] and
  // flux[i] hold it (else read vol6[i] and moment[i] as 0; an empty piece has no flux)
  unsigned integrated = 0;
  unsigned surfaced = 0;  // bit j: surface[j] holds the faces on face j (else read it as 0)
  // [sub-tet k][slot s][own node a]: ∫ 4 lambda_k lambda_a dS * 24 (physical area) over piece k's
  // face on the plane it shares with sub-tet s (lambda_k = lambda_s), for left-out pieces s only
  double flux[4][4][4];
  // [sub-tet k][slot s]: unit normal of that plane out of sub-tet k (where flux[k][s] is written)
  Vec3 flux_normal[4][4];
};

inline ContactPairResult zero_result() {
  ContactPairResult r;
  for (int v = 0; v < 4; ++v) {
    r.force_contactor[v].setZero();
    r.force_target[v].setZero();
  }
  r.normal.setZero();
  r.centroid.setZero();
  return r;
}

// The overlap centroid (its barycentric weights in both tets, from the contactor side's moments
// vol_integral[0][i][c] = ∫ over piece i of carried value c) and the normal force, once the
// nodal forces are in `r`.
inline void finish_pair_result(const TetPairFrame& frame, const double (&vol_integral)[2][4][8],
                               ContactPairResult& r) {
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
}

}  // namespace fdem::piece_clip
