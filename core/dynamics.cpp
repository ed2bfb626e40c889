#include "core/dynamics.hpp"

#include <Eigen/SVD>
#include <cmath>

#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

// The per-tet kernel is too large for the compiler's inlining heuristics; inlining it into the
// element loop anyway (GCC, Clang) saves the call and the TetForce copy: ~5-10 % on the stage.
#if defined(__GNUC__)
#define FDEM_INLINE_CALLEES __attribute__((flatten))
#else
#define FDEM_INLINE_CALLEES
#endif

template <class Material>
FDEM_INLINE_CALLEES inline void tet_force_into(const Model& model, LocalIndex t,
                                               const Material& material, double* corner,
                                               InternalForceSummary& sum) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  const double viscosity = tets.viscosity[t];
  Vec3 x[4], v[4];
  for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * t + c]);
  // The kernel reads velocities only for viscous damping: skip that gather when undamped.
  if (viscosity > 0.0)
    for (int c = 0; c < 4; ++c) v[c] = vec3_at(nodes.v.data(), tets.nodes[4 * t + c]);
  const Eigen::Map<const Mat3> dm_inv(tets.dm_inv.data() + 9 * t);
  const TetForce out = tet_internal_force(x, v, dm_inv, tets.volume0[t], material, viscosity);
  for (int c = 0; c < 4; ++c) vec3_at(corner, c) = out.force[c];
  sum.strain_energy += out.strain_energy;
  sum.damping_power += out.damping_power;
  if (!(out.jacobian >= sum.min_jacobian)) {  // NaN counts as worst
    sum.min_jacobian = out.jacobian;
    sum.min_jacobian_tet = t;
  }
}

}  // namespace

InternalForceSummary compute_internal_forces(const Model& model,
                                             std::vector<double>& corner_forces) {
  const TetArrays& tets = model.tets;
  const LocalIndex n_tets = tets.size();
  corner_forces.resize(12 * static_cast<std::size_t>(n_tets));
  InternalForceSummary sum;
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const MaterialProperties& mat = model.materials[tets.material[t]];
    double* corner = corner_forces.data() + 12 * static_cast<std::size_t>(t);
    if (mat.model == ElasticModel::neo_hookean)
      tet_force_into(model, t, NeoHookean{mat.lame}, corner, sum);
    else
      tet_force_into(model, t, StVenantKirchhoff{mat.lame}, corner, sum);
  }
  return sum;
}

void gather_corner_forces(const NodeCornerMap& map, const std::vector<double>& corner_forces,
                          std::vector<double>& f) {
  const LocalIndex n_nodes = static_cast<LocalIndex>(map.offsets.size()) - 1;
  for (LocalIndex n = 0; n < n_nodes; ++n) {
    double fx = 0.0, fy = 0.0, fz = 0.0;
    for (LocalIndex s = map.offsets[n]; s < map.offsets[n + 1]; ++s) {
      const double* c = corner_forces.data() + 3 * static_cast<std::size_t>(map.slots[s]);
      fx += c[0];
      fy += c[1];
      fz += c[2];
    }
    f[3 * n] = fx;
    f[3 * n + 1] = fy;
    f[3 * n + 2] = fz;
  }
}

void add_gravity(const Vec3& gravity, NodeArrays& nodes) {
  for (LocalIndex n = 0; n < nodes.size(); ++n)
    for (int k = 0; k < 3; ++k) nodes.f[3 * n + k] += nodes.mass[n] * gravity[k];
}

IntegrationSummary integrate_central_difference(double dt, NodeArrays& nodes) {
  IntegrationSummary out;
  double kinetic2 = 0.0, max_dx2 = 0.0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    const double m = nodes.mass[n];
    const std::uint8_t mask = nodes.constrained[n];
    double dx2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * static_cast<std::size_t>(n) + k;
      const double v_old = nodes.v[i];
      double v_new = v_old + dt * nodes.f[i] / m;
      if (mask & (1u << k)) {
        v_new = nodes.prescribed_velocity[i];
        const double reaction = m * (v_new - v_old) / dt - nodes.f[i];
        out.constraint_work_before += 0.5 * reaction * dt * v_old;
        out.constraint_work_after += 0.5 * reaction * dt * v_new;
      }
      kinetic2 += m * v_old * v_new;
      out.momentum_before[k] += m * v_old;
      out.momentum_after[k] += m * v_new;
      nodes.v[i] = v_new;
      const double dx = dt * v_new;
      nodes.x[i] += dx;
      dx2 += dx * dx;
    }
    max_dx2 = std::max(max_dx2, dx2);
  }
  out.kinetic_energy = 0.5 * kinetic2;
  out.max_displacement_increment = std::sqrt(max_dx2);
  out.finite = std::isfinite(kinetic2);
  return out;
}

std::vector<PieceMotion> piece_motions(const Model& model) {
  const NodeArrays& nodes = model.nodes;
  const std::size_t n_pieces = model.pieces.size();
  std::vector<PieceMotion> motion(n_pieces);
  std::vector<double> mass(n_pieces, 0.0);
  std::vector<Vec3> reference_centroid(n_pieces, Vec3::Zero());
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    const std::int32_t p = nodes.piece[n];
    const double m = nodes.mass[n];
    mass[p] += m;
    motion[p].centroid += m * vec3_at(nodes.x.data(), n);
    motion[p].velocity += m * vec3_at(nodes.v.data(), n);
    reference_centroid[p] += m * vec3_at(nodes.x0.data(), n);
  }
  std::vector<Mat3> covariance(n_pieces, Mat3::Zero());
  for (std::size_t p = 0; p < n_pieces; ++p)
    if (mass[p] > 0.0) {
      motion[p].centroid /= mass[p];
      motion[p].velocity /= mass[p];
      reference_centroid[p] /= mass[p];
    }
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    const std::int32_t p = nodes.piece[n];
    covariance[p] += nodes.mass[n] * (vec3_at(nodes.x.data(), n) - motion[p].centroid) *
                     (vec3_at(nodes.x0.data(), n) - reference_centroid[p]).transpose();
  }
  // Best-fit rotation (Kabsch): R = U·diag(1,1,det)·Vᵀ from the mass-weighted covariance.
  for (std::size_t p = 0; p < n_pieces; ++p) {
    Eigen::JacobiSVD<Mat3> svd(covariance[p], Eigen::ComputeFullU | Eigen::ComputeFullV);
    Mat3 d = Mat3::Identity();
    d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
    const Mat3 R = svd.matrixU() * d * svd.matrixV().transpose();
    const Eigen::AngleAxisd aa(R);
    motion[p].rotation = aa.angle() * aa.axis();
  }
  return motion;
}

Vec3 linear_momentum(const NodeArrays& nodes) {
  Vec3 p = Vec3::Zero();
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) p += nodes.mass[n] * vec3_at(nodes.v.data(), n);
  return p;
}

Vec3 angular_momentum(const NodeArrays& nodes) {
  Vec3 l = Vec3::Zero();
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    l += nodes.mass[n] * vec3_at(nodes.x.data(), n).cross(vec3_at(nodes.v.data(), n));
  return l;
}

}  // namespace fdem
