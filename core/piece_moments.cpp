#include "core/piece_moments.hpp"

#include <Eigen/SVD>
#include <algorithm>

namespace fdem {

namespace {
Vec3 vec3_value(const ExactSum (&sums)[3]) {
  return Vec3(sums[0].value(), sums[1].value(), sums[2].value());
}
}  // namespace

void PieceMoments::add(const PieceMoments& other) {
  mass.add(other.mass);
  for (int k = 0; k < 3; ++k) {
    position[k].add(other.position[k]);
    momentum[k].add(other.momentum[k]);
    reference[k].add(other.reference[k]);
  }
}

void PieceMoments::append_words(std::vector<std::int64_t>& out) const {
  mass.append_words(out);
  for (const ExactSum* sums : {position, momentum, reference})
    for (int k = 0; k < 3; ++k) sums[k].append_words(out);
}

PieceMoments PieceMoments::from_words(const std::int64_t*& words) {
  PieceMoments m;
  m.mass = ExactSum::from_words(words);
  for (ExactSum* sums : {m.position, m.momentum, m.reference})
    for (int k = 0; k < 3; ++k) sums[k] = ExactSum::from_words(words);
  return m;
}

PieceCentres centres_of(const PieceMoments& moments) {
  PieceCentres c;
  const double mass = moments.mass.value();
  if (!(mass > 0.0)) return c;
  c.centroid = vec3_value(moments.position) / mass;
  c.velocity = vec3_value(moments.momentum) / mass;
  c.reference = vec3_value(moments.reference) / mass;
  return c;
}

void PieceSpread::add(const PieceSpread& other) {
  for (int i = 0; i < 9; ++i) covariance[i].add(other.covariance[i]);
}

void PieceSpread::append_words(std::vector<std::int64_t>& out) const {
  for (const ExactSum& s : covariance) s.append_words(out);
}

PieceSpread PieceSpread::from_words(const std::int64_t*& words) {
  PieceSpread s;
  for (ExactSum& c : s.covariance) c = ExactSum::from_words(words);
  return s;
}

Vec3 rotation_of(const PieceSpread& spread) {
  Mat3 covariance;
  for (int i = 0; i < 9; ++i) covariance.data()[i] = spread.covariance[i].value();
  // R = U·diag(1, 1, det)·Vᵀ from the mass-weighted covariance.
  Eigen::JacobiSVD<Mat3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Mat3 R = svd.matrixU() * d * svd.matrixV().transpose();
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Without per-node scratch beyond the node list (a frame's bodies.csv rows of a large jointed body
// had 8 B per node more at the run's peak): the pieces are collected run by run (a piece's nodes
// are mostly consecutive), and a node's slot is looked up in the counting and in the placing pass.
OwnedPieces owned_pieces(const NodeArrays& nodes) {
  OwnedPieces owned;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    if (owned.ids.empty() || owned.ids.back() != nodes.piece[n])
      owned.ids.push_back(nodes.piece[n]);
  std::sort(owned.ids.begin(), owned.ids.end());
  owned.ids.erase(std::unique(owned.ids.begin(), owned.ids.end()), owned.ids.end());
  owned.ids.shrink_to_fit();
  const auto slot_of = [&](LocalIndex n) {
    return static_cast<std::size_t>(
        std::lower_bound(owned.ids.begin(), owned.ids.end(), nodes.piece[n]) - owned.ids.begin());
  };
  // Counting sort of the owned nodes by their piece's slot (stable: ascending nodes per piece).
  owned.first.assign(owned.ids.size() + 1, 0);
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) ++owned.first[slot_of(n) + 1];
  for (std::size_t i = 0; i < owned.ids.size(); ++i) owned.first[i + 1] += owned.first[i];
  std::vector<std::int32_t> next(owned.first.begin(), owned.first.end() - 1);
  owned.nodes.resize(static_cast<std::size_t>(nodes.n_owned));
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    owned.nodes[static_cast<std::size_t>(next[slot_of(n)]++)] = n;
  return owned;
}

PieceMoments piece_moments(const NodeArrays& nodes, const OwnedPieces& owned, std::size_t i) {
  PieceMoments s;
  for (std::int32_t k = owned.first[i]; k < owned.first[i + 1]; ++k) {
    const LocalIndex n = owned.nodes[static_cast<std::size_t>(k)];
    const double m = nodes.mass[n];
    s.mass.add(m);
    for (int d = 0; d < 3; ++d) {
      s.position[d].add(m * nodes.x[3 * n + d]);
      s.momentum[d].add(m * nodes.v[3 * n + d]);
      s.reference[d].add(m * nodes.x0(n)[d]);
    }
  }
  return s;
}

PieceSpread piece_spread(const NodeArrays& nodes, const OwnedPieces& owned, std::size_t i,
                         const PieceCentres& c) {
  PieceSpread s;
  for (std::int32_t k = owned.first[i]; k < owned.first[i + 1]; ++k) {
    const LocalIndex n = owned.nodes[static_cast<std::size_t>(k)];
    const Mat3 outer = nodes.mass[n] * (vec3_at(nodes.x.data(), n) - c.centroid) *
                       (nodes.x0(n) - c.reference).transpose();
    for (int j = 0; j < 9; ++j) s.covariance[j].add(outer.data()[j]);
  }
  return s;
}

}  // namespace fdem
