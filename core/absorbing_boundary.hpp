// Viscous absorbing boundaries (Lysmer & Kuhlemeyer 1969; scene key `absorbing:`): on the mesh's
// boundary faces in a chosen region, dashpots of ρ·c_p (normal) and ρ·c_s (tangential) per unit
// area resist the face's velocity, so a plane wave reaching the face at normal incidence leaves
// the model instead of reflecting.  Each face's dashpot is lumped to its three nodes (A/3 each).
//
// Which faces: a face of a tet that no other tet shares (by its three nodes) and that no cohesive
// joint bonds, with all three nodes inside the region's box at t = 0 (and of a listed body).  A
// rank decides this for the faces that touch a node it owns: every tet around such a node is held
// there (docs/parallel.md), so its count of the face's tets is the whole model's.  Forces are
// needed only at owned nodes, so no face list travels: it is found again after every
// redistribution (`rebind`).  The dashpots act on v_{n−½} (central difference stores half-step
// velocities) and are added after gravity, face by face in ascending (tet gid, face), so an owned
// node's force is the same sum in the same order on any rank count.
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// The lumped dashpot forces (N) on the three nodes of one face: f_i = −(A/3)·(ρc_p·(v_i·n)n +
// ρc_s·(v_i − (v_i·n)n)), with n the unit normal, A the area (m²), z_p = ρc_p and z_s = ρc_s the
// impedances (Pa·s/m).  v: 3 × 3 velocities (m/s); f: 3 × 3 forces, overwritten.
inline void lk_face_forces(const double* const v[3], const Vec3& n, double area, double z_p,
                           double z_s, double f[9]) {
  const double share = area / 3.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 vi(v[i][0], v[i][1], v[i][2]);
    const double vn = vi.dot(n);
    const Vec3 fi = -share * (z_p * vn * n + z_s * (vi - vn * n));
    for (int k = 0; k < 3; ++k) f[3 * i + k] = fi[k];
  }
}

struct AbsorbingFace {
  LocalIndex tet = 0;
  std::int32_t face = 0;        // the face opposite the tet's node `face`
  Vec3 normal = Vec3::Zero();   // unit, outward, at t = 0
  double area = 0.0;            // m², at t = 0
  double z_p = 0.0, z_s = 0.0;  // Pa·s/m: ρ·c_p and ρ·c_s of the tet's material
  std::int32_t spec = 0;        // the first `absorbing:` entry that selects it
};

// The absorbing faces this rank applies (module comment), in ascending (tet gid, face).
std::vector<AbsorbingFace> find_absorbing_faces(const std::vector<AbsorbingSpec>& specs,
                                                const Model& model);

class AbsorbingBoundary {
 public:
  AbsorbingBoundary(std::vector<AbsorbingSpec> specs, const Model& model);
  void rebind(const Model& model);  // the model's tets or nodes changed (redistribution)

  // Adds the dashpot forces at v_{n−½} to nodes.f; returns the dissipation over x_{n−1} → x_n
  // of the owned nodes, ½dt·Σ −f·v_{n−½} (J).  Keeps the forces for `dissipation_after`.
  double add_forces(double dt, Model& model);
  // After the integration: ½dt·Σ −f·v_{n+½} over the owned nodes (J).
  double dissipation_after(double dt, const Model& model) const;

  // The largest c/m (1/s) over this rank's owned nodes, c the node's summed normal impedance·A/3:
  // the damping ratio at the highest mode ω is c/(2mω) (time-step reduction, as for viscosity).
  double max_rate(const Model& model) const;
  // Per spec: the faces this rank counts (each face on exactly one rank: the owner of its node of
  // smallest gid) and their area (m²) — summed over ranks, the whole boundary's.
  std::vector<std::int64_t> counted_faces(const Model& model) const;
  std::vector<double> counted_area(const Model& model) const;

 private:
  std::vector<AbsorbingSpec> specs_;
  std::vector<AbsorbingFace> faces_;
  std::vector<LocalIndex> nodes_;   // owned nodes touched by a face, ascending
  std::vector<double> force_;       // 3 per entry of nodes_: this step's dashpot force (N)
  std::vector<std::int32_t> slot_;  // per local node: its entry in nodes_, or −1
};

}  // namespace fdem
