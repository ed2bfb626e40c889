// What a histories.csv row holds, as sums over this process's owned nodes and values of the
// tets it owns (drivers/histories turns them into rows; parallel/exact_sum_reduction adds the
// ranks' sums).  Sums are exact (core/exact_sum), so a row does not depend on how the nodes are
// spread over ranks.  Read between the forces and the integration of a step: x = x_n, v =
// v_n−½ (the project's half-step velocity), f = f(x_n) without the supports.
#pragma once

#include <array>

#include "core/exact_sum.hpp"
#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// Sums over the nodes of one load or body: Σm (kg), Σm·(x − x0) (kg·m) and a force (N).
struct GroupSums {
  ExactSum mass, moment[3], force[3];
};

// Whether local node n is one of the nodes `load` holds (region: inside the box at t = 0;
// bodies: a node of one of them).
bool load_holds_node(const LoadSpec& load, const Model& model, LocalIndex n);

// A load's owned nodes: force = the support's reaction Σ m·(v_prescribed − v)/dt − f over the
// components the load prescribes (what the support exerts on the model; −f at a constant
// velocity).  dt: the step about to be integrated (s).
void add_load_sums(const LoadSpec& load, const Model& model, double dt, GroupSums& sums);

// A body's owned nodes: force = Σ f, the resultant of the contact, joint and gravity forces on
// it (its internal forces cancel), without its supports' reactions.
void add_body_sums(std::int32_t body, const Model& model, GroupSums& sums);

// Barycentric coordinates (λ0..λ3, Σ = 1) of the reference point X in local tet t's shape at
// t = 0.
std::array<double, 4> reference_barycentric(const Model& model, LocalIndex t, const Vec3& X);

// Lowest gid of this process's owned tets whose reference shape holds X (every λ ≥ −1e-9), or
// −1.  A point on a face or edge shared by tets goes to the lowest gid on any rank count.
GlobalId owned_tet_holding(const Model& model, const Vec3& X);

// A monitor's values: displacement (m) and velocity (m/s) interpolated linearly at X in local
// tet t, and the tet's Cauchy stress (Pa, elastic, constant in a linear tet).
struct MonitorValues {
  Vec3 displacement = Vec3::Zero(), velocity = Vec3::Zero();
  Mat3 stress = Mat3::Zero();
};
MonitorValues monitor_values(const Model& model, LocalIndex t, const Vec3& X);

}  // namespace fdem
