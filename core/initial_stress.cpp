#include "core/initial_stress.hpp"

#include <algorithm>
#include <cmath>

#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

Mat3 tensor_of(const double* s) {
  Mat3 m;
  m << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
  return m;
}

}  // namespace

std::vector<double> initial_stresses(const std::vector<InitialStressSpec>& specs,
                                     const Vec3& gravity, const Model& model) {
  const TetArrays& tets = model.tets;
  std::vector<double> s0(6 * static_cast<std::size_t>(tets.size()), 0.0);
  if (specs.empty()) return s0;
  const double g = gravity.norm();
  const Vec3 down = g > 0.0 ? Vec3(gravity / g) : Vec3::Zero();
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    const int body = model.pieces.body_of(tets.piece[t]);
    const InitialStressSpec* spec = nullptr;
    for (const InitialStressSpec& s : specs)
      if (s.bodies.empty() || std::find(s.bodies.begin(), s.bodies.end(), body) != s.bodies.end()) {
        spec = &s;
        break;
      }
    if (!spec) continue;
    double* out = &s0[6 * static_cast<std::size_t>(t)];
    if (spec->kind == InitialStressSpec::Kind::uniform) {
      for (int k = 0; k < 6; ++k) out[k] = spec->stress[k];
      continue;
    }
    Vec3 centroid = Vec3::Zero();
    for (int c = 0; c < 4; ++c)
      centroid += 0.25 * model.nodes.x0(tets.nodes[4 * static_cast<std::size_t>(t) + c]);
    // Height along −g; ground above the tet: surface − height (none above the surface).
    const double depth = std::max(spec->surface + down.dot(centroid), 0.0);
    const double rho = model.materials[static_cast<std::size_t>(tets.material[t])].density;
    const double vertical = -rho * g * depth, horizontal = spec->k0 * vertical;  // Pa
    const Mat3 s =
        horizontal * Mat3::Identity() + (vertical - horizontal) * down * down.transpose();
    const double v[6] = {s(0, 0), s(1, 1), s(2, 2), s(1, 2), s(0, 2), s(0, 1)};
    for (int k = 0; k < 6; ++k) out[k] = v[k];
  }
  return s0;
}

InitialStressForces add_initial_stress_forces(const std::vector<double>& s0, Model& model) {
  InitialStressForces out;
  NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  for (LocalIndex t : model.tet_force_order) {
    const double* s = &s0[6 * static_cast<std::size_t>(t)];
    if (s[0] == 0.0 && s[1] == 0.0 && s[2] == 0.0 && s[3] == 0.0 && s[4] == 0.0 && s[5] == 0.0)
      continue;
    const LocalIndex* n = &tets.nodes[4 * static_cast<std::size_t>(t)];
    Vec3 x[4];
    for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), n[c]);
    const Eigen::Map<const Mat3> dm_inv(tets.dm_inv.data() + 9 * static_cast<std::size_t>(t));
    const Mat3 F = edge_matrix(x) * dm_inv;
    const Mat3 S = tensor_of(s);
    const double volume0 = tets.volume0[t];
    const Mat3 H = -volume0 * (F * S) * dm_inv.transpose();
    const Vec3 f[4] = {-(H.col(0) + H.col(1) + H.col(2)), H.col(0), H.col(1), H.col(2)};
    for (int c = 0; c < 4; ++c) vec3_at(nodes.f.data(), n[c]) += f[c];
    if (tets.is_owned(t)) {
      const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
      out.energy += volume0 * S.cwiseProduct(E).sum();
    }
  }
  return out;
}

EquilibriumSums equilibrium_sums(const std::vector<double>& total_force,
                                 const std::vector<double>& stress_force, const NodeArrays& nodes) {
  EquilibriumSums e;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    for (int k = 0; k < 3; ++k) {
      if (nodes.constrained[static_cast<std::size_t>(n)] & (1u << k)) continue;
      const std::size_t i = 3 * static_cast<std::size_t>(n) + static_cast<std::size_t>(k);
      e.residual += total_force[i] * total_force[i];
      e.scale += stress_force[i] * stress_force[i];
    }
  return e;
}

}  // namespace fdem
