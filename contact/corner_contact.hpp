// Corner contact (scene key contact.formulation: corners): each corner of a tet face on the
// surface of its contact group against each facing surface face of the other tet, with a penalty
// spring per corner.  Potential contact spreads a pressed joint's force over the overlap; when a
// joint opens at a hinge its thrust then acts on a wedge of overlap inside the hinge's edge, and
// a blocky structure collapses early (docs/verification.md, "Corner contact").  Here the thrust
// of an opening hinge stays on the corners at its edge.
//
// Corner p of face S (tet s, outward normal n_S) against face T (tet t, outward normal n_T, n_S ·
// n_T < −½): depth g = (p − x_T)·n_T; for −½ min(h_S, h_T) < g < 0 and p over T it stores
//     U = ½ k g²,   k = ½ · 4p(1/h_S + 1/h_T) · min(A_S, A_T)/3   (N/m; p the penalty, Pa)
// with h the tets' reference altitudes over the faces and A the faces' reference areas (the
// smaller, so that a large face's corner on a small face loads its nodes no more than their own
// area would).  Both tets take both roles, hence the ½: a joint pressed face on face has
// potential contact's stiffness per area, 4p(1/h_S + 1/h_T).  The forces are U's exact
// gradient: −k g n_T on p, and +k g μ_j n_T on T's corners, μ the barycentric weights of p's foot
// on T (a plane turning about the foot does not change g to first order).
//
// Which face holds a corner is decided from the pair alone, the same way on every rank and in
// any order of the pairs: p lies over T when it is inside each of T's edges seen along n_S.  An
// edge's test is oriented by its nodes' global ids, so the two faces that share it evaluate the
// same number and exactly one of them takes a corner on either side of it; a corner exactly on
// an edge or vertex (conforming meshes put corners on the other block's vertices) goes where a
// fixed infinitesimal shift in the plane of S puts it (simulation of simplicity), one face of a
// flat patch.  Beyond a fold of T's surface (a block's edge) a corner less deep than a reach of
// kFoldTolerance × its own tet's altitude is held up to that reach outside, so that a hinge's
// corner sitting on the edge keeps its contact as it turns: by the face whose fold edge it lies
// beside, and within twice the reach of a fold vertex (a block's corner, or where faces meet along
// its edge) by the one face that owns the vertex's zone (core/contact_faces.hpp), so that no two
// faces ever hold it.
#pragma once

#include <cstdint>

#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_overlap.hpp"
#include "core/contact_faces.hpp"
#include "core/model.hpp"
#include "core/types.hpp"

namespace fdem {

// A travel (m) beyond any that a run makes: the pair can never give corner contact.
constexpr double kUnboundedTravel = 1e300;

// How far beyond a fold a corner is held, as a fraction of its tet's altitude over its face.
constexpr double kFoldTolerance = 0.02;

// The least ratio of the contact dashpot under corner contact in a quasi-static run.  A contact
// held at a few corners rings at their springs' frequency where an overlap's integral does not,
// and under local damping (f − α|f| sign v) a ringing node acts as dry friction on the slow
// motion: the tilting-table wall stood at 1.02 of its collapse angle with no dashpot, and turned
// at 1.01 with this one (docs/verification.md, "Corner contact").
constexpr double kCornerDampingRatio = 0.1;

// What the kernel needs of one tet besides its current geometry: its contact_faces bits, its
// nodes' global ids (to orient edges alike on every rank), and per face the reference area
// (m²) and 1/altitude (1/m).
struct CornerTet {
  std::uint64_t faces = 0;  // contact_face_bits
  GlobalId node_gid[4] = {0, 0, 0, 0};
  double area0[4] = {0, 0, 0, 0};
  double inverse_height0[4] = {0, 0, 0, 0};
};

// Whether point p, seen along the unit normal n of the face it is a corner of, lies over face
// `face` of `target` (the claim rule above; the face's surface bit is not looked at).  `reach`
// (m): how far beyond a fold a corner is held (kFoldTolerance × the altitude of the corner's tet
// over its face), if it lies less than that under the face's plane; within twice that of a fold
// vertex the vertex's zone owner holds it.
bool corner_over_face(const Vec3& p, const Vec3& n, double reach, const TetGeometry& target,
                      const CornerTet& corner_target, int face);

// Tet t's CornerTet: TetArrays::contact_faces, node gids, and the reference shape's face areas
// and altitudes.
CornerTet corner_tet(const Model& model, LocalIndex t);

// How far (m, in the sum of the two tets' corner travels; ApartPairs) the pair's tets can move
// and still give no corner contact, for a pair that gives none now: unbounded when one tet has
// no surface face (its contact_faces bits do not change), else, when no surface face of one
// faces a surface face of the other (n_s·n_t ≥ −½ for all), the travel that cannot turn any two
// of them to face each other.  Moving a face's corners by at most δ changes its doubled area
// vector by at most 2δ(|e1| + |e2|) + 4δ² ≤ 4δ(L + δ) (e1, e2 two of its edges, L its longest),
// so its unit normal turns by at most θ with sin θ ≤ 2δ(L + δ)/A (A its area) and moves by at
// most θ ≤ (π/2) sin θ; n_s·n_t then drops by at most π·2δ(L + δ)/A over the pair's worst faces,
// which stays below the margin min(n_s·n_t + ½) while δ ≤ margin·A/(4πL) (≤ L).  0 otherwise
// (a pair with facing faces is evaluated every step).
double corner_pair_apart_travel(const TetGeometry& a, const CornerTet& corner_a,
                                const TetGeometry& b, const CornerTet& corner_b);

// The pair's corner contact as a ContactPairResult: forces and energy as above; normal: the
// direction of the resultant on the first tet; centroid: the force-weighted mean of the corners
// in contact, with its (clamped) barycentric weights in both tets, where friction and the
// dashpot act; overlap_volume: Σ A_S/3·|g| (m³), a measure of the contact.
ContactPairResult corner_contact(const TetGeometry& a, const CornerTet& corner_a,
                                 const TetGeometry& b, const CornerTet& corner_b, double penalty);

}  // namespace fdem
