#include "contact/corner_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdem {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Accumulator {
  ContactPairResult& result;
  Vec3 point_sum = Vec3::Zero();  // Σ |f| p (N·m)
  double weight_sum = 0.0;        // Σ |f| (N)
};

// Two directions in the plane normal to n: the fixed infinitesimal shift that decides a corner
// lying exactly on an edge's line (first along d1, then along d2).
void tie_directions(const Vec3& n, Vec3& d1, Vec3& d2) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n[k]) < std::abs(n[axis])) axis = k;
  d1 = n.cross(Vec3::Unit(axis));
  d2 = n.cross(d1);
}

// The sign of n·(edge × (p − x_u)) for p moved by ε·d1 + ε²·d2 (ε → 0): the side of the line
// through x_u along `edge` on which p lies, decided alike by every face that has the line.
double side_of(const Vec3& n, const Vec3& edge, const Vec3& from_line, const Vec3& d1,
               const Vec3& d2) {
  double side = n.dot(edge.cross(from_line));
  if (side == 0.0) side = n.dot(edge.cross(d1));
  if (side == 0.0) side = n.dot(edge.cross(d2));
  return side;
}

// Whether p, seen along n, lies over face T = (w0, w1, w2) of `target`; `reach` (m): how far
// beyond a fold p may lie if it is `shallow` (less than reach under T's plane).
//  - Shallow and near a fold vertex of T's side of the surface (within 2·reach, across n), only
//    the owner of the vertex's zone holds p: every face at the vertex sees the same disc.
//  - Inside T's folds, by the sides of its three edges: each edge (u, v) is taken from its smaller
//    node gid, so the faces on its two sides compute the same side of p.
//  - Shallow and beyond a fold edge (by less than reach), where p lies along it: between its
//    ends.  A deeper corner beyond a fold lies beside the other body, not in it.
bool over_face(const Vec3& p, const Vec3& n, const Vec3& d1, const Vec3& d2, double reach,
               bool shallow, const TetGeometry& target, const CornerTet& corner, int face,
               const int w[3]) {
  for (int c = 0; c < 3 && shallow; ++c) {
    if (!(corner.faces & contact_face_bits::fold_vertex(face, c))) continue;
    const Vec3 r = p - target.corners.x[w[c]];
    if ((r - r.dot(n) * n).squaredNorm() <= 4.0 * reach * reach)
      return (corner.faces & contact_face_bits::zone_owner(face, c)) != 0;
  }
  bool inside = true;
  int beyond = 0;  // bit e: p lies beyond fold edge e
  for (int e = 0; e < 3; ++e) {
    int u = w[(e + 1) % 3], v = w[(e + 2) % 3];
    if (corner.node_gid[v] < corner.node_gid[u]) std::swap(u, v);
    const Vec3& xu = target.corners.x[u];
    const Vec3 edge = target.corners.x[v] - xu;
    const double side_of_face = n.dot(edge.cross(target.corners.x[w[e]] - xu));
    if (!(side_of_face != 0.0)) return false;  // T seen edge-on (or not finite)
    const double side_of_p = side_of(n, edge, p - xu, d1, d2);
    if (side_of_face > 0.0 ? side_of_p > 0.0 : side_of_p < 0.0) continue;
    if (!(corner.faces & contact_face_bits::fold(face, e))) {
      inside = false;
      continue;
    }
    const double outside = std::abs(n.dot(edge.cross(p - xu)));  // |edge| × distance (m²)
    if (!shallow || !(outside < reach * std::sqrt(edge.squaredNorm()))) return false;
    beyond |= 1 << e;
  }
  if (!beyond) return inside;
  for (int e = 0; e < 3; ++e) {
    if (!(beyond >> e & 1)) continue;
    const Vec3& x0 = target.corners.x[w[(e + 1) % 3]];
    const Vec3 edge = target.corners.x[w[(e + 2) % 3]] - x0;
    const double along = (p - x0).dot(edge);  // m², 0 at one end, |edge|² at the other
    if (!(along >= 0.0 && along <= edge.squaredNorm())) return false;
  }
  return true;
}

// Whether a corner deeper than the reach under face T (its foot's weights mu) lies nearer to a
// fold edge of T than under T: it went in through the face beyond that fold, where its depth is
// less (blocks meeting at right angles: a corner beside a block's edge is not pressed into the
// face it passes by).
bool entered_beside(double g, const double mu[3], double twice_area, const TetGeometry& target,
                    const CornerTet& corner, int face, const int w[3]) {
  for (int e = 0; e < 3; ++e) {
    if (!(corner.faces & contact_face_bits::fold(face, e))) continue;
    const double edge =
        (target.corners.x[w[(e + 2) % 3]] - target.corners.x[w[(e + 1) % 3]]).norm();
    if (-g > mu[e] * twice_area / edge) return true;  // depth against distance to the edge (m)
  }
  return false;
}

// The corners of `side`'s surface faces against `other`'s surface faces; `side_is_first`: the
// forces on `side` go to force_contactor.
void corners_against_faces(const TetGeometry& side, const CornerTet& corner_side,
                           const TetGeometry& other, const CornerTet& corner_other, double penalty,
                           bool side_is_first, Accumulator& acc) {
  ContactPairResult& r = acc.result;
  Vec3* f_side = side_is_first ? r.force_contactor : r.force_target;
  Vec3* f_other = side_is_first ? r.force_target : r.force_contactor;
  for (int s = 0; s < 4; ++s) {
    if (!(corner_side.faces & contact_face_bits::surface(s))) continue;
    const Vec3 n_s = -side.inward_normal[s];
    int cs[3];
    face_corners(s, cs);
    bool tie_ready = false;  // the tie directions, made for the first corner in reach
    Vec3 d1, d2;
    for (int t = 0; t < 4; ++t) {
      if (!(corner_other.faces & contact_face_bits::surface(t))) continue;
      const Vec3 n_t = -other.inward_normal[t];
      if (!(n_s.dot(n_t) < -0.5)) continue;  // not facing each other
      int w[3];
      face_corners(t, w);
      const Vec3& x0 = other.corners.x[w[0]];
      const double deepest =
          0.5 / std::max(corner_side.inverse_height0[s], corner_other.inverse_height0[t]);
      double g[3];
      bool any = false;
      for (int q = 0; q < 3; ++q) {
        g[q] = (side.corners.x[cs[q]] - x0).dot(n_t);
        any |= g[q] < 0.0 && g[q] > -deepest;
      }
      if (!any) continue;  // no corner of S within the depth T holds
      if (!tie_ready) {
        tie_directions(n_s, d1, d2);
        tie_ready = true;
      }
      const double reach = kFoldTolerance / corner_side.inverse_height0[s];  // m, beyond a fold
      // Half a pressed face's stiffness per area (each tet takes each role) times A_S/3 (N/m).
      const double k = 2.0 * penalty *
                       (corner_side.inverse_height0[s] + corner_other.inverse_height0[t]) *
                       std::min(corner_side.area0[s], corner_other.area0[t]) / 3.0;
      const Vec3 e1 = other.corners.x[w[1]] - x0, e2 = other.corners.x[w[2]] - x0;
      const double twice_area = n_t.dot(e1.cross(e2));
      for (int q = 0; q < 3; ++q) {
        if (!(g[q] < 0.0 && g[q] > -deepest)) continue;
        const Vec3& p = side.corners.x[cs[q]];
        if (!over_face(p, n_s, d1, d2, reach, -g[q] < reach, other, corner_other, t, w)) continue;
        const Vec3 foot = p - g[q] * n_t;
        const double mu1 = n_t.dot((foot - x0).cross(e2)) / twice_area;
        const double mu2 = n_t.dot(e1.cross(foot - x0)) / twice_area;
        const double mu[3] = {1.0 - mu1 - mu2, mu1, mu2};
        if (!(-g[q] < reach) && entered_beside(g[q], mu, twice_area, other, corner_other, t, w))
          continue;
        r.energy += 0.5 * k * g[q] * g[q];
        const Vec3 f = -k * g[q] * n_t;  // on the corner, out of the other tet
        f_side[cs[q]] += f;
        for (int j = 0; j < 3; ++j) f_other[w[j]] -= mu[j] * f;
        r.overlap_volume += corner_side.area0[s] / 3.0 * -g[q];
        const double weight = f.norm();
        acc.point_sum += weight * p;
        acc.weight_sum += weight;
      }
    }
  }
}

// Barycentric weights of x in the tet, clamped to [0, 1] and normalised: where a force at x is
// spread on the tet's nodes (x may lie just outside it).
void clamped_weights(const TetGeometry& tet, const Vec3& x, double out[4]) {
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    const int j = (k + 1) % 4;  // a corner where λ_k = 0
    out[k] = std::clamp(tet.gradient[k].dot(x - tet.corners.x[j]), 0.0, 1.0);
    sum += out[k];
  }
  for (int k = 0; k < 4; ++k) out[k] = sum > 0.0 ? out[k] / sum : 0.25;
}

}  // namespace

bool corner_over_face(const Vec3& p, const Vec3& n, double reach, const TetGeometry& target,
                      const CornerTet& corner_target, int face) {
  Vec3 d1, d2;
  tie_directions(n, d1, d2);
  int w[3];
  face_corners(face, w);
  return over_face(p, n, d1, d2, reach, true, target, corner_target, face, w);
}

CornerTet corner_tet(const Model& model, LocalIndex t) {
  CornerTet out;
  const std::size_t at = 2 * static_cast<std::size_t>(t);
  out.faces =
      static_cast<std::uint32_t>(model.tets.contact_faces[at]) |
      static_cast<std::uint64_t>(static_cast<std::uint32_t>(model.tets.contact_faces[at + 1]))
          << 32;
  TetCorners reference;
  for (int c = 0; c < 4; ++c) {
    const LocalIndex node = model.tets.nodes[4 * t + c];
    out.node_gid[c] = model.nodes.gid[node];
    reference.x[c] = model.nodes.x0(node);
  }
  Vec3 gradient[4];
  double edge_det = 0.0;
  if (!barycentric_gradients(reference, gradient, edge_det)) {
    out.faces = 0;  // a flat reference tet: nothing to press
    return out;
  }
  const double volume = std::abs(edge_det) / 6.0;
  for (int f = 0; f < 4; ++f) {
    out.inverse_height0[f] = gradient[f].norm();           // |∇λ_f| = 1/h_f
    out.area0[f] = 3.0 * volume * out.inverse_height0[f];  // V = A h / 3
  }
  return out;
}

double corner_pair_apart_travel(const TetGeometry& a, const CornerTet& corner_a,
                                const TetGeometry& b, const CornerTet& corner_b) {
  if (!(corner_a.faces & 0xFu) || !(corner_b.faces & 0xFu)) return kUnboundedTravel;
  if (!a.valid || !b.valid) return 0.0;
  double margin = std::numeric_limits<double>::infinity();  // min over face pairs of n_s·n_t + ½
  for (int s = 0; s < 4; ++s)
    for (int t = 0; t < 4; ++t)
      if ((corner_a.faces & contact_face_bits::surface(s)) &&
          (corner_b.faces & contact_face_bits::surface(t)))
        margin = std::min(margin, a.inward_normal[s].dot(b.inward_normal[t]) + 0.5);
  if (!(margin > 1e-12)) return 0.0;  // faces that face each other (or NaN): evaluated each step
  double longest = 0.0, smallest_area = std::numeric_limits<double>::infinity();  // m, m²
  const auto face_size = [&](const TetGeometry& tet, int face) {
    int w[3];
    face_corners(face, w);
    const Vec3 e1 = tet.corners.x[w[1]] - tet.corners.x[w[0]];
    const Vec3 e2 = tet.corners.x[w[2]] - tet.corners.x[w[0]];
    const Vec3 e3 = tet.corners.x[w[2]] - tet.corners.x[w[1]];
    longest = std::max({longest, e1.norm(), e2.norm(), e3.norm()});
    smallest_area = std::min(smallest_area, 0.5 * e1.cross(e2).norm());
  };
  for (int f = 0; f < 4; ++f) {
    if (corner_a.faces & contact_face_bits::surface(f)) face_size(a, f);
    if (corner_b.faces & contact_face_bits::surface(f)) face_size(b, f);
  }
  // (inward normals: their dot is the outward normals'; margin ≤ 0 or NaN: no travel; 1e-12
  // covers the round-off of the dots, here and in the kernel)
  const double travel = (margin - 1e-12) * smallest_area / (4.0 * kPi * longest) * (1.0 - 1e-9);
  return travel > 0.0 ? travel : 0.0;
}

ContactPairResult corner_contact(const TetGeometry& a, const CornerTet& corner_a,
                                 const TetGeometry& b, const CornerTet& corner_b, double penalty) {
  ContactPairResult r;
  if (!a.valid || !b.valid || !(corner_a.faces & 0xFu) || !(corner_b.faces & 0xFu)) return r;
  Accumulator acc{r};
  corners_against_faces(a, corner_a, b, corner_b, penalty, true, acc);
  corners_against_faces(b, corner_b, a, corner_a, penalty, false, acc);
  if (!(acc.weight_sum > 0.0)) return ContactPairResult{};
  r.overlapping = true;
  Vec3 resultant = Vec3::Zero();
  for (int c = 0; c < 4; ++c) resultant += r.force_contactor[c];
  r.normal_force = resultant.norm();
  r.normal = r.normal_force > 0.0 ? Vec3(resultant / r.normal_force) : Vec3::Zero();
  r.centroid = acc.point_sum / acc.weight_sum;
  clamped_weights(a, r.centroid, r.centroid_weights_contactor);
  clamped_weights(b, r.centroid, r.centroid_weights_target);
  return r;
}

}  // namespace fdem
