#include "core/time_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

// The current shape of tet t (recomputed in the second passes rather than stored: 80 B per tet).
TetReference current_shape(const Model& model, LocalIndex t) {
  Vec3 x[4];
  for (int c = 0; c < 4; ++c) x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
  return tet_reference(x);
}

}  // namespace

CriticalStep critical_time_step(const Model& model) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  const LocalIndex n_tets = tets.size();

  // Pass 1: each tet's stiffness weight (its largest K eigenvalue, N/m) and the weight per node.
  std::vector<double> weight(n_tets, 0.0), node_weight(nodes.size(), 0.0);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetReference current = current_shape(model, t);
    if (!(current.volume > 0.0)) continue;  // inverted: the force stage reports it
    weight[t] = tet_max_stiffness_eigenvalue(current.dm_inv, current.volume,
                                             model.materials[tets.material[t]].lame);
    for (int c = 0; c < 4; ++c) node_weight[tets.nodes[4 * t + c]] += weight[t];
  }

  // Pass 2: λ_max(M_e⁻¹K_e) with the node masses split in proportion to the weights.
  CriticalStep out;
  out.dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < n_tets; ++t) {
    // Each tet counts once, on its owner (whose halo holds every tet around its nodes).
    if (weight[t] <= 0.0 || !tets.is_owned(t)) continue;
    double corner_mass[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      corner_mass[c] = nodes.mass[n] * weight[t] / node_weight[n];
    }
    const MaterialProperties& mat = model.materials[tets.material[t]];
    const TetReference current = current_shape(model, t);
    const double omega =
        std::sqrt(tet_max_eigenvalue(current.dm_inv, current.volume, mat.lame, corner_mass));
    const double dt = critical_step_for_frequency(omega, mat.damping_ratio);
    if (dt < out.dt) {
      out.dt = dt;
      out.limiting_tet = t;
    }
  }
  return out;
}

namespace {

// For a symmetric positive semi-definite G: λ_max(V·BᵀCB) of a tet whose shape gradients, each
// divided by the square root of its corner mass, have second moments G.  In G's eigenbasis
// (s1, s2, s3; C is isotropic) BBᵀ is diagonal and the spectrum splits into the normal block
// 2μ·S + λ·uuᵀ (u_i = √s_i) and the shear values μ(s_j + s_k) ≤ 2μ·s_max.
struct StiffnessBounds {
  double lower, upper;  // N/m (or 1/s² with masses)
};
StiffnessBounds stiffness_bounds(const Mat3& G, double volume, LameParameters lame) {
  const double trace = G.trace();
  const double mean = trace / 3.0;
  // s_max ≤ mean + √(2/3·|G − mean·I|²) (Samuelson), and ≤ the largest absolute row sum.
  const double deviator_sq = (G - mean * Mat3::Identity()).squaredNorm();
  const double rows = G.cwiseAbs().rowwise().sum().maxCoeff();
  const double s_max = std::min(mean + std::sqrt(2.0 / 3.0 * deviator_sq), rows);
  StiffnessBounds out;
  // Weyl: λ_max(2μS + λuuᵀ) ≤ 2μ·s_max + max(λ, 0)·|u|², |u|² = tr G.
  out.upper = volume * (2.0 * lame.mu * s_max + std::max(lame.lambda, 0.0) * trace);
  // A diagonal entry (2μ + λ)·s_max and a shear value μ·max(s_j + s_k), both ≥ their share of tr G.
  out.lower = volume * std::max(2.0 * lame.mu + lame.lambda, 2.0 * lame.mu) * mean;
  return out;
}

// The smallest float not below x (+infinity beyond float's range).
float float_at_least(double x) {
  if (!(x <= std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

Mat3 second_moments(const Eigen::Matrix<double, 3, 4>& g, const double (&corner_mass)[4]) {
  Mat3 G = Mat3::Zero();
  for (int a = 0; a < 4; ++a) G += g.col(a) * g.col(a).transpose() / corner_mass[a];
  return G;
}

}  // namespace

double critical_time_step_lower_bound(const Model& model) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  const LocalIndex n_tets = tets.size();
  const double unit[4] = {1.0, 1.0, 1.0, 1.0};
  // Bounds of a tet's weight (critical_time_step's λ_max with unit masses), computed in each pass
  // rather than stored (16 B per tet at the run's memory peak).
  const auto weight_of = [&](LocalIndex t, const TetReference& current) {
    if (!(current.volume > 0.0)) return StiffnessBounds{0.0, 0.0};  // not in the exact split either
    return stiffness_bounds(second_moments(shape_gradients(current.dm_inv), unit), current.volume,
                            model.materials[tets.material[t]].lame);
  };
  // Pass 1: the sum of the upper bounds at each node, held in single precision rounded up (an
  // upper bound still; 4 B per node instead of 8).
  std::vector<float> node_upper(static_cast<std::size_t>(nodes.size()), 0.0f);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const double upper = weight_of(t, current_shape(model, t)).upper;
    if (upper <= 0.0) continue;
    for (int c = 0; c < 4; ++c) {
      float& sum = node_upper[static_cast<std::size_t>(tets.nodes[4 * t + c])];
      sum = float_at_least(static_cast<double>(sum) + upper);
    }
  }
  // Pass 2: the corner mass m·w/(w + Σ others) is at least m·w_lo/(w_lo + Σ others' upper bounds)
  // (the sum, taken as a difference, is rounded up by a relative 1e-12).
  double dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < n_tets; ++t) {
    if (!tets.is_owned(t)) continue;
    const TetReference current = current_shape(model, t);
    const StiffnessBounds weight = weight_of(t, current);
    if (weight.upper <= 0.0) continue;
    double corner_mass[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      const double sum = node_upper[static_cast<std::size_t>(n)];
      const double others = std::max(0.0, sum - weight.upper) * (1.0 + 1e-12);
      corner_mass[c] = nodes.mass[n] * weight.lower / (weight.lower + others);
    }
    const MaterialProperties& mat = model.materials[tets.material[t]];
    const double omega_sq =
        stiffness_bounds(second_moments(shape_gradients(current.dm_inv), corner_mass),
                         current.volume, mat.lame)
            .upper;
    dt = std::min(dt, critical_step_for_frequency(std::sqrt(omega_sq), mat.damping_ratio));
  }
  // Where the inequalities are equalities (an isotropic G: a regular tet alone at its nodes) the
  // two computations round differently; the margin keeps the bound below.
  return dt * (1.0 - 1e-9);
}

}  // namespace fdem
