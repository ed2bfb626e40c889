// Exact potential contact between two tets; see potential_contact_kernels.hpp for the formulas.
#include <algorithm>
#include <cmath>

#include "contact/clip_replay.hpp"
#include "contact/pair_force_bound.hpp"
#include "contact/piece_clipper.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "core/lanes.hpp"

namespace fdem {
namespace {

using namespace piece_clip;

// Zeroes w[0, n): the first 16 (a piece has ~8 vertices) by a fixed-size store the compiler
// writes out inline, where a loop to n would become a call to memset.
inline void zero_weights(double (&w)[kMaxVertices], int n) {
  static_assert(kMaxVertices >= 16);
  std::fill_n(w, 16, 0.0);
  for (int v = 16; v < n; ++v) w[v] = 0.0;
}

// Accumulates one piece (sub-tet `own_sub` clipped; its n vertices in the clipper's order and its
// faces, from a fresh clip or its replay): cone sums over all faces from an apex at the piece's
// first vertex (a point of the piece: no cancellation between remote cones, so slivers
// of overlap keep full relative precision), and the surface integrals on the faces that lie on
// the other tet's faces.  Both sums are linear in the vertex values, so each fan triangle only
// adds scalar weights to its three vertices; the values (8 per vertex) are weighted once at the
// end.  `moments`: how many carried values need their moment (4: own only, 8: own and other).
// area_weight[j]: maps a barycentric-space doubled area vector to the doubled physical area
// projected on face j's outward unit normal.
template <int moments>
void integrate_piece(const PieceVertex* const* vertex, int n, const PieceFaces& faces, int own_sub,
                     const double (&area_weight)[4][3], const double (&side_weight)[4][3],
                     unsigned flux_slots, SideIntegrals& out) {
  double volume_weight[kMaxVertices];      // Σ vol6 of the cones having the vertex on their base
  double surface_weight[4][kMaxVertices];  // per other face: Σ area × (f_k + Σf) of its triangles
  bool on_face[4] = {false, false, false, false};
  double flux_weight[4][kMaxVertices];  // per side slot s in flux_slots: as surface_weight
  bool on_side[4] = {false, false, false, false};
  zero_weights(volume_weight, n);
  const double* apex = vertex[0]->lam;  // apex: the first vertex of the piece
  double piece_vol6 = 0.0;
  const std::uint8_t* at = faces.bytes;
  for (int f = 0; f < faces.count; at += 3 + at[0], ++f) {
    const int nf = at[0];
    const unsigned face_planes = PieceFaces::planes_of(at);
    const std::uint8_t* face = at + 3;
    int other_face = -1;
    if (face_planes & kOtherFaceBits) {
      const unsigned bits = (face_planes & kOtherFaceBits) >> kOtherFaceShift;
      other_face = __builtin_ctz(bits);  // (the lowest face: bits is not 0)
      if (!on_face[other_face]) {
        on_face[other_face] = true;
        zero_weights(surface_weight[other_face], n);
      }
    }
    int side_slot = -1;  // a face on the plane shared with a left-out piece's sub-tet
    if (const unsigned side = (face_planes >> 1) & flux_slots & 0xFu) {
      side_slot = __builtin_ctz(side);
      if (!on_side[side_slot]) {
        on_side[side_slot] = true;
        zero_weights(flux_weight[side_slot], n);
      }
    }
    // A face through the apex starts at it (walk_faces walks the apex's three faces first, from
    // the apex): its cones are flat, vol6 = 0 · area = ±0, which adds nothing to sums that start
    // at +0.  Such a face is integrated only where it carries a surface or flux term.
    const bool through_apex = face[0] == 0;
    if (through_apex && other_face < 0 && side_slot < 0) continue;
    // Fan from the face's first vertex.
    const double* x0 = vertex[face[0]]->lam;
    const double h0[3] = {x0[1] - apex[1], x0[2] - apex[2], x0[3] - apex[3]};
    for (int k = 1; k + 1 < nf; ++k) {
      const double* x1 = vertex[face[k]]->lam;
      const double* x2 = vertex[face[k + 1]]->lam;
      const double u[3] = {x1[1] - x0[1], x1[2] - x0[2], x1[3] - x0[3]};
      const double w[3] = {x2[1] - x0[1], x2[2] - x0[2], x2[3] - x0[3]};
      const double area2[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                               u[0] * w[1] - u[1] * w[0]};
      if (!through_apex) {
        const double vol6 = h0[0] * area2[0] + h0[1] * area2[1] + h0[2] * area2[2];
        piece_vol6 += vol6;
        volume_weight[face[0]] += vol6;
        volume_weight[face[k]] += vol6;
        volume_weight[face[k + 1]] += vol6;
      }
      // ∫_tri f g dS = A/12 (sum f_k g_k + (sum f)(sum g)), f = 4 lambda_own, g any carried
      // value: vertex k carries A (f_k + sum f), A the triangle's area on the plane that
      // `weight` projects onto.
      const auto add_quadratic = [&](const double* weight, double* vertex_weight) {
        const double area_phys2 =
            area2[0] * weight[0] + area2[1] * weight[1] + area2[2] * weight[2];
        const double f0 = 4.0 * x0[own_sub], f1 = 4.0 * x1[own_sub], f2 = 4.0 * x2[own_sub];
        const double fsum = f0 + f1 + f2;
        vertex_weight[face[0]] += area_phys2 * (f0 + fsum);
        vertex_weight[face[k]] += area_phys2 * (f1 + fsum);
        vertex_weight[face[k + 1]] += area_phys2 * (f2 + fsum);
      };
      if (other_face >= 0)  // the other tet's face: g = lambda_other_b
        add_quadratic(area_weight[other_face], surface_weight[other_face]);
      if (side_slot >= 0)  // the plane shared with a left-out sub-tet: g = lambda_own_a
        add_quadratic(side_weight[side_slot], flux_weight[side_slot]);
    }
  }
  volume_weight[0] += piece_vol6;  // the apex term: vol6 of the piece times the apex's values
  out.vol6[own_sub] = piece_vol6;  // one piece per sub-tet
  out.integrated |= 1u << own_sub;
  // The sums below run over the vertices four values side by side (one vector lane each, each
  // lane rounding as alone).
  Lanes moment[moments / 4] = {};
  for (int v = 0; v < n; ++v) {
    const Lanes wv = splat(volume_weight[v]);
    for (int h = 0; h < moments / 4; ++h) moment[h] += wv * load_lanes(vertex[v]->lam + 4 * h);
  }
  for (int h = 0; h < moments / 4; ++h) store_lanes(moment[h], out.moment[own_sub] + 4 * h);
  for (int slot = 0; slot < 4; ++slot) {
    if (!((flux_slots >> slot) & 1u)) continue;
    Lanes sum = {};
    if (on_side[slot])
      for (int v = 0; v < n; ++v) sum += flux_weight[slot][v] * load_lanes(vertex[v]->lam);
    store_lanes(sum, out.flux[own_sub][slot]);
  }
  for (int j = 0; j < 4; ++j) {
    if (!on_face[j]) continue;
    Lanes sum = (out.surfaced >> j) & 1u ? load_lanes(out.surface[j]) : Lanes{};
    out.surfaced |= 1u << j;
    for (int v = 0; v < n; ++v) sum += surface_weight[j][v] * load_lanes(vertex[v]->lam + 4);
    store_lanes(sum, out.surface[j]);
  }
}

// The entry of piece `key` in the pair's record from the step before ([key][length][bytes]), or
// null.  Pieces are looked up in the kernel's order, so the search resumes where it stopped.
const std::uint8_t* find_recorded_piece(ClipMemo& memo, unsigned key) {
  const std::uint8_t*& at = memo.previous;
  while (at && memo.previous_end - at >= 2 && at[0] < key) at += 2 + at[1];
  return at && memo.previous_end - at >= 2 && at[0] == key ? at : nullptr;
}

// Appends a piece's clip record ([key][length][bytes]) to this step's record of the pair.
void record_piece(RecordBytes& record, unsigned key, const std::uint8_t* bytes, int length) {
  record.append_pair(static_cast<std::uint8_t>(key), static_cast<std::uint8_t>(length));
  record.append(bytes, static_cast<std::size_t>(length));
}

// The inward unit normals of the pair's faces: [0] contactor, [1] target (as TetGeometry's).
struct PairNormals {
  const Vec3* of[2];
};

// The four vertices of sub-tet i, [i][slot]: own corners s != i and the centroid in slot i, with
// their own barycentric coordinates, neighbours and planes (the other tet's coordinates are the
// pair's, filled in per pair).  In lambda_1..3 coordinates the own tet is the unit simplex
// (positive), and replacing corner i by the centroid keeps the orientation, so kTetNeighbours
// applies unchanged.  Slot s lies on the three faces opposite the other slots: the face opposite
// slot i is the base (own face i), the face opposite slot k != i a side through the centroid.
struct SubTetVertices {
  PieceVertex v[4][4];
};
constexpr SubTetVertices make_sub_tet_vertices() {
  SubTetVertices table{};
  for (int i = 0; i < 4; ++i)
    for (int s = 0; s < 4; ++s) {
      PieceVertex& v = table.v[i][s];
      for (int a = 0; a < 4; ++a) v.lam[a] = (s == i) ? 0.25 : (a == s ? 1.0 : 0.0);
      for (int b = 0; b < 4; ++b) v.lam[4 + b] = 0.0;
      for (int e = 0; e < 3; ++e) v.next[e] = kTetNeighbours[s][e];
      unsigned planes = 0;
      for (int s2 = 0; s2 < 4; ++s2)
        if (s2 != s) planes |= (s2 == i) ? kOuterFaceBit : (1u << (1 + s2));
      v.planes = planes;
    }
  return table;
}
constexpr SubTetVertices kSubTetVertices = make_sub_tet_vertices();

// Integrates the four pieces (sub-tet i of `own`) ∩ other.
void integrate_side(const TetPairFrame& frame, const PairNormals& normals, int own, int moments,
                    unsigned left_out, ClipMemo* memo, SideIntegrals& out) {
  const BarycentricMap& own_map = frame.map[own];
  const double(&other_at_corner)[4][4] = frame.lambda_other[own];
  const double(&own_at_other_corner)[4][4] = frame.lambda_other[1 - own];
  // Other tet's barycentrics at the own centroid: the corner average (so that a corner set
  // outside a face plane keeps the centroid outside too, consistent with the rejection test).
  double other_at_centroid[4];
  for (int b = 0; b < 4; ++b)
    other_at_centroid[b] = 0.25 * (other_at_corner[0][b] + other_at_corner[1][b] +
                                   other_at_corner[2][b] + other_at_corner[3][b]);
  // Doubled area vector in own-barycentric space -> doubled physical area along the outward unit
  // normal n_j of the other tet's face j: Nanson, n dS = |det D| D^-T N dS_lambda (the absolute
  // value keeps "outward" outward for either orientation); rows of D^-1 are grad lambda_1..3.
  double area_weight[4][3];
  for (int j = 0; j < 4; ++j) {
    const Vec3 normal = -normals.of[1 - own][j];
    for (int k = 0; k < 3; ++k)
      area_weight[j][k] = std::abs(own_map.edge_det) * own_map.gradient[k + 1].dot(normal);
  }
  // This side's left-out pieces: each kept piece i also integrates its face on the plane
  // lambda_i = lambda_s it shares with a left-out sub-tet s (SideIntegrals::flux); side_weight[s]
  // maps the fan's area to that plane's, whose unit normal points out of sub-tet i.
  const unsigned flux_slots = (left_out >> (4 * own)) & 0xFu;
  // Quick rejection of a piece: its four vertices strictly outside one plane of the other tet, or
  // the other tet's four corners strictly outside one side plane of the sub-tet (lambda_i <=
  // lambda_k inside it).  Either way the piece has no volume.  Sub-tet i's vertices are the
  // corners s != i and the centroid.  The planes side by side (one vector lane each): lane b of
  // outside[s], whether own corner s (s = 4: the centroid) lies outside the other tet's plane b.
  LaneMask outside[5];
  for (int s = 0; s < 4; ++s) outside[s] = load_lanes(other_at_corner[s]) < 0.0;
  outside[4] = load_lanes(other_at_centroid) < 0.0;
  Piece piece;
  for (int i = 0; i < 4; ++i) {
    if ((left_out >> (4 * own + i)) & 1u) continue;
    // Lane b: the sub-tet's four vertices outside plane b.  Lane k: the other tet's four corners
    // where lambda_i > lambda_k, outside sub-tet i's side k.
    LaneMask all_outside = outside[4];
    for (int s = 0; s < 4; ++s)
      if (s != i) all_outside &= outside[s];
    LaneMask all_beyond = load_lanes(own_at_other_corner[0]) < own_at_other_corner[0][i];
    for (int v = 1; v < 4; ++v)
      all_beyond &= load_lanes(own_at_other_corner[v]) < own_at_other_corner[v][i];
    all_beyond &= lane_index() != i;  // (not a side of its own)
    const LaneMask either = all_outside | all_beyond;
    const bool empty = (either[0] | either[1] | either[2] | either[3]) != 0;
    if (empty) continue;
    // Sub-tet i = own corners k != i plus the centroid in slot i (kSubTetVertices).
    piece.count = 4;
    for (int s = 0; s < 4; ++s) {
      PieceVertex& v = piece.v[s];
      v = kSubTetVertices.v[i][s];
      const double* other = (s == i) ? other_at_centroid : other_at_corner[s];
      for (int b = 0; b < 4; ++b) v.lam[4 + b] = other[b];
    }
    // The piece's clip: replayed where every vertex kept its side of every plane, from the pair's
    // record of the step before (clip_replay.hpp) or else from a clip met before by any pair
    // (clip_topologies.hpp); clipped afresh (and kept for the next time) where none fits.
    const unsigned key = 4u * static_cast<unsigned>(own) + static_cast<unsigned>(i);
    const PieceVertex* vertex[kMaxVertices];
    int n_vertices = 0;
    PieceFaces faces;
    const std::uint8_t* entry = memo ? find_recorded_piece(*memo, key) : nullptr;
    const std::uint8_t* clip = entry ? entry + 2 : nullptr;  // the clip replayed, and its length
    int clip_length = entry ? entry[1] : 0;
    Replay replay = clip ? replay_piece(piece, clip, clip + clip_length, vertex, n_vertices, faces)
                         : Replay::side_changed;
    ClipTopologies* const topologies = memo ? memo->topologies : nullptr;
    if (replay == Replay::side_changed && topologies) {
      std::uint32_t terminal = ClipTopologies::kNone;
      replay = walk_topologies(piece, i, *topologies, terminal, vertex, n_vertices, faces);
      if (replay != Replay::side_changed) {
        ++memo->found;
        clip = topologies->record(terminal);
        clip_length = topologies->record_length(terminal);
      }
    }
    bool alive = replay == Replay::kept;
    bool walked = alive;
    if (replay != Replay::side_changed) {
      ++memo->replayed;
      if (memo->record) record_piece(*memo->record, key, clip, clip_length);
    } else {
      ClipLog log;
      ClipLog* const logged = memo && memo->record ? &log : nullptr;
      alive = true;
      for (int b = 0; b < 4 && alive; ++b)
        alive = clip_piece(piece, 4 + b, 1u << (kOtherFaceShift + b), logged);
      walked = alive && walk_faces(piece, faces);
      if (walked) {
        n_vertices = piece.count;
        for (int v = 0; v < n_vertices; ++v) vertex[v] = &piece.v[v];
      }
      if (memo) ++memo->clipped;
      if (logged && alive == walked) {
        if (walked) log_faces(faces, log);
        if (log.valid) {
          record_piece(*memo->record, key, log.bytes, log.size);
          if (topologies) topologies->add(i, log.bytes, log.size);
        }
      }
    }
    if (walked) {  // (alive but not walked: a corrupted graph, cannot happen; nothing to add)
      double side_weight[4][3];  // set for the slots in `slots`, read for those only
      const unsigned slots = flux_slots & ~(1u << i);
      for (int slot = 0; slot < 4; ++slot) {
        if (!((slots >> slot) & 1u)) continue;
        const Vec3& normal = out.flux_normal[i][slot] =
            (own_map.gradient[i] - own_map.gradient[slot]).normalized();
        for (int k = 0; k < 3; ++k)
          side_weight[slot][k] = std::abs(own_map.edge_det) * own_map.gradient[k + 1].dot(normal);
      }
      if (moments == 8)
        integrate_piece<8>(vertex, n_vertices, faces, i, area_weight, side_weight, slots, out);
      else
        integrate_piece<4>(vertex, n_vertices, faces, i, area_weight, side_weight, slots, out);
    }
  }
}

// The inward unit normals computed from the frame's gradients (paths without TetGeometry).
PairNormals unit_normals(const TetPairFrame& frame, Vec3 (&normals)[2][4]) {
  for (int s = 0; s < 2; ++s)
    for (int a = 0; a < 4; ++a) normals[s][a] = frame.map[s].gradient[a].normalized();
  return PairNormals{{normals[0], normals[1]}};
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
// The integration built for AVX2 and for the x86-64 baseline, chosen when the program loads;
// flatten: all of it is inlined into each clone (the rejections before it stay lean).  Without FMA
// contraction (-ffp-contract=off) and without reassociation both round alike: the same results bit
// for bit.
#define FDEM_CONTACT_CLONES __attribute__((target_clones("avx2", "default"), flatten))
#else
#define FDEM_CONTACT_CLONES
#endif

// The pair's frame and its face-plane test, built alike: every candidate pair the boxes pass
// comes here.
FDEM_CONTACT_CLONES bool prepare_pair(const PreparedContactor& contactor, const TetGeometry& target,
                                      TetPairFrame& frame, int first_plane, int* separating_plane) {
  return prepare_tet_pair(contactor, target, frame, first_plane, separating_plane);
}

// The sliver bounds, built alike.
FDEM_CONTACT_CLONES unsigned negligible_parts_of(const TetPairFrame& frame,
                                                 const PairMetrics& metrics, double tolerance,
                                                 bool kept_before) {
  return negligible_parts(frame, metrics, tolerance, kept_before);
}

FDEM_CONTACT_CLONES ContactPairResult assemble(const TetPairFrame& frame,
                                               const PairNormals& normals, double penalty,
                                               unsigned left_out = 0, ClipMemo* memo = nullptr) {
  ContactPairResult r = zero_result();

  SideIntegrals side[2];
  // (side 0 carries the other tet's moments too: they give the centroid's weights)
  integrate_side(frame, normals, 0, 8, left_out, memo, side[0]);
  integrate_side(frame, normals, 1, 4, left_out, memo, side[1]);

  // Physical volume integrals: ∫_{piece i} lam_c dV = |det| * moment / 24 (moment includes the
  // apex term vol6 * lam_c(apex)).
  double vol_integral[2][4][8];  // [side][sub-tet][carried value]
  double volume[2] = {0.0, 0.0};
  for (int s = 0; s < 2; ++s) {
    const double jac = std::abs(frame.map[s].edge_det);
    const int carried = s == 0 ? 8 : 4;  // the target's side carries its own values only
    for (int i = 0; i < 4; ++i) {
      if (!((side[s].integrated >> i) & 1u)) {  // no piece: zero, as jac * 0 would give
        for (int c = 0; c < carried; ++c) vol_integral[s][i][c] = 0.0;
        continue;
      }
      for (int c = 0; c < carried; ++c)
        vol_integral[s][i][c] = jac * side[s].moment[i][c] * (1.0 / 24.0);
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
    const Vec3* inward_normal = normals.of[s];  // of own face i: grad lambda_i / |grad lambda_i|
    // The four nodes side by side (one vector lane each), each summed in the same order as alone.
    Lanes f[3] = {};  // [component], lane a: node a
    // A term a sub-tet does not have (no piece; no surface on its face) adds only zeros and is
    // passed over: f never holds -0 (it starts at +0, and a sum that cancels rounds to +0).
    for (int i = 0; i < 4; ++i) {
      if ((side[s].integrated >> i) & 1u) {  // volume term: grad phi = 4 grad lambda_i on piece i
        const Vec3& gradient = own.gradient[i];
        const Lanes term = 4.0 * load_lanes(vol_integral[s][i]);
        for (int k = 0; k < 3; ++k) f[k] += term * gradient[k];
      }
      if ((other_side.surfaced >> i) & 1u) {    // on own face i: - ∫ phi_other lambda_a n dS
        const Vec3& normal = inward_normal[i];  // n: the outward unit normal is -normal
        const Lanes term = load_lanes(other_side.surface[i]) * (1.0 / 24.0);
        for (int k = 0; k < 3; ++k) f[k] += term * normal[k];
      }
    }
    for (int k = 0; k < 3; ++k) f[k] = penalty * f[k];
    // The pieces' forces sum to the gradient of the energy because the boundary term
    // -p ∫ phi lambda_a n dS on the face two sub-tets share cancels between their pieces.  A
    // left-out piece i leaves it to each kept neighbour k, over k's face on their plane (normal
    // out of k, phi = 4 lambda_k there): the forces stay the exact gradient of the kept energy.
    for (unsigned out = (left_out >> (4 * s)) & 0xFu; out; out &= out - 1) {
      const int i = __builtin_ctz(out);
      // (an empty piece shares nothing; a left-out one is not integrated)
      for (unsigned kept = side[s].integrated & ~(1u << i); kept; kept &= kept - 1) {
        const int k = __builtin_ctz(kept);
        const Vec3& normal = side[s].flux_normal[k][i];
        const Lanes flux = penalty * load_lanes(side[s].flux[k][i]) * (1.0 / 24.0);
        for (int c = 0; c < 3; ++c) f[c] -= flux * normal[c];
      }
    }
    for (int a = 0; a < 4; ++a) force[s][a] = Vec3(f[0][a], f[1][a], f[2][a]);
  }
  energy *= 4.0 * penalty;

  r.overlapping = true;
  r.energy = energy;
  r.overlap_volume = volume[0];
  finish_pair_result(frame, vol_integral, r);
  return r;
}

}  // namespace

ContactPairResult potential_contact(const PreparedContactor& contactor, const TetGeometry& target,
                                    double penalty, double sliver_tolerance, ClipMemo* memo) {
  TetPairFrame frame;
  int plane = -1;
  if (!prepare_pair(contactor, target, frame,
                    memo ? memo->apart_before - ClipMemo::kApartAtPlane : -1,
                    memo ? &plane : nullptr)) {
    if (plane >= 0) {
      memo->apart_now = static_cast<std::uint8_t>(ClipMemo::kApartAtPlane + plane);
      memo->apart_gap = face_plane_gap(contactor, target, plane / 4, plane % 4);
    }
    return zero_result();
  }
  const PairMetrics metrics{{&contactor.metrics, &target.metrics}};
  const unsigned left_out =
      sliver_tolerance > 0.0
          ? negligible_parts_of(frame, metrics, sliver_tolerance, memo && memo->previous)
          : 0u;
  if (left_out == kEveryPiece) return zero_result();
  // Apart at the step before though the face planes passed it: an edge–edge axis, mostly.
  if (memo && memo->apart_before != ClipMemo::kNotApart &&
      memo->apart_before < ClipMemo::kApartAtPlane) {
    const int hint = memo->apart_before - ClipMemo::kApartAtAxis;  // negative: none
    const int axis =
        clearly_separating_edge_axis(frame.local[0], frame.local[1], hint, &memo->apart_gap);
    if (axis >= 0) {
      memo->apart_now = static_cast<std::uint8_t>(ClipMemo::kApartAtAxis + axis);
      return zero_result();
    }
  }
  Vec3 normals[2][4];  // where a tet came without its own
  if (!contactor.has_normals || !target.has_normals) unit_normals(frame, normals);
  const PairNormals pair_normals{{contactor.has_normals ? contactor.inward_normal : normals[0],
                                  target.has_normals ? target.inward_normal : normals[1]}};
  ContactPairResult result = assemble(frame, pair_normals, penalty, left_out, memo);
  if (memo && !result.overlapping) memo->apart_now = ClipMemo::kClippedEmpty;
  return result;
}

ContactPairResult potential_contact(const TetCorners& contactor, const TetCorners& target,
                                    double penalty, double sliver_tolerance) {
  if (!tet_boxes_intersect(contactor, target)) return zero_result();
  PreparedContactor prepared;
  prepare_contactor(contactor, prepared);
  TetGeometry geometry;
  compute_tet_geometry(target, geometry, false);
  return potential_contact(prepared, geometry, penalty, sliver_tolerance);
}

ContactPairResult potential_contact_without(const TetCorners& contactor, const TetCorners& target,
                                            double penalty, unsigned left_out) {
  TetPairFrame frame;
  if (!prepare_tet_pair(contactor, target, frame)) return zero_result();
  Vec3 normals[2][4];
  const PairNormals pair_normals = unit_normals(frame, normals);
  return assemble(frame, pair_normals, penalty, left_out);
}

ContactPairResult potential_contact_unculled(const TetCorners& contactor, const TetCorners& target,
                                             double penalty) {
  TetPairFrame frame;
  if (!frame_maps_from_corners(contactor, target, frame)) return zero_result();
  barycentric_at_corners(frame.map[1], frame.local[0], frame.lambda_other[0]);
  barycentric_at_corners(frame.map[0], frame.local[1], frame.lambda_other[1]);
  Vec3 normals[2][4];
  const PairNormals pair_normals = unit_normals(frame, normals);
  return assemble(frame, pair_normals, penalty);
}

}  // namespace fdem
