// Time-dependent loads (scene `loads:`): ground motion from an acceleration record, tilting
// tables, horizontal-acceleration ramps and prescribed velocities with a time history.
// LoadSchedule::apply is the one place where they are evaluated each step; constant prescribed
// velocities stay in apply_constraints.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"
#include "core/surface_loads.hpp"

namespace fdem {

// Reads a CSV acceleration record, rows "time, acceleration" (s, record units).  Blank lines,
// lines starting with '#' and one header line before the first data row are skipped.  Throws
// InputError naming the file and line for anything else that is not two numbers, for times
// that do not increase, negative times, or fewer than two rows.
void read_acceleration_record(const std::string& path, BaseMotionSpec& spec);

// Ground velocity (m/s, along spec.direction) at time t: the exact integral from 0 of the
// acceleration scale·a(t), a linear between samples and zero before the first and after the last
// sample (so the velocity holds its final value).
double base_velocity(const BaseMotionSpec& spec, double t);

// Gravity at time t: scene gravity turned by the tilts (in scene order), plus the ramps.
Vec3 gravity_at(const Scene& scene, double t);

// Tilt angle (rad) and ramp acceleration (m/s²) at time t.
double tilt_angle(const TiltSpec& tilt, double t);
double ramp_acceleration(const RampSpec& ramp, double t);

// When the loads stop changing: quasi_static.equilibrium_ratio ends a run only from then on (an
// equilibrium reached before a tilt starts or while a ramp rises is not the answer asked for).
struct LoadsSettle {
  double time = 0.0;    // s: no load changes from this time on (infinity: one never stops)
  int load = -1;        // scene index of the load that changes last (-1: none changes)
  bool moving = false;  // that load prescribes a non-zero velocity to the end (a moving boundary)
};
// A base motion counts by its record given in code (LoadSchedule::settle has the ones read from
// files too).
LoadsSettle loads_settle(const std::vector<LoadSpec>& loads);
// The one of the two that settles later.
LoadsSettle later(const LoadsSettle& a, const LoadsSettle& b);
// "load 'table', a tilt, changes until t = 4.02 s" / "..., keeps its boundary moving to the end".
std::string describe_loads_settle(const Scene& scene, const LoadsSettle& settle);
// "load 'NAME'", or "loads[i]" for a load without a name (scene index i).
std::string load_label(const Scene& scene, int index);

class LoadSchedule {
 public:
  // Reads the records not given in code and lists the nodes each base motion moves.
  LoadSchedule(const Scene& scene, const Model& model);

  bool changes_gravity() const { return changes_gravity_; }
  bool moves_bases() const { return !bases_.empty(); }
  bool active() const { return changes_gravity_ || moves_bases() || !varying_.empty(); }
  bool has_surface_loads() const { return !surfaces_.empty(); }

  // Sets the model's loads for the step from t to t + dt: gravity at t (forces at t), base
  // nodes' and varying loads' prescribed velocity at t + dt/2 (central difference stores
  // half-step velocities).
  void apply(double t, double dt, Model& model) const;

  // Surface loads (stage 6): adds each one's face forces at time t (s) to the nodes, in scene
  // order, and returns nothing; surface_power then gives Σ F·v over the owned corners (W) for the
  // work: before the integration with v(t − dt/2), after it with v(t + dt/2).
  void add_surface_forces(double t, Model& model);
  double surface_power(const Model& model) const;
  double surface_force_magnitude() const;  // N, Σ over the owned faces' corners
  // When the loads stop changing (base motions by their records, read once here).
  const LoadsSettle& settle() const { return settle_; }
  // When the ground first moves: the earliest time from which a base motion's acceleration is
  // not zero (`time`, s; infinity without one) and that load's scene index (`load`, -1: none).
  const LoadsSettle& base_motion_start() const { return base_motion_start_; }
  // Per surface load (scene order): its index in the scene's loads and the number of faces
  // whose tet is owned here (to refuse a load that acts on no face).
  std::vector<std::pair<int, std::int64_t>> surface_face_counts() const;

  const Scene& scene() const { return scene_; }
  // The model's nodes changed (parallel redistribution): list the base nodes again.
  void rebind(const Model& model);

 private:
  struct Base {
    BaseMotionSpec motion;
    std::vector<std::int32_t> bodies;
    std::vector<LocalIndex> nodes;
  };
  // A prescribed velocity × history(t): the nodes and components it sets (a later load in the
  // scene that holds the same component sets it instead, as in apply_constraints).
  struct Varying {
    LoadSpec load;
    int index = -1;  // in the scene's loads
    std::vector<LocalIndex> nodes;
    std::vector<std::uint8_t> masks;
  };
  Scene scene_;  // gravity, tilts and ramps (records filled)
  std::vector<Base> bases_;
  std::vector<Varying> varying_;
  struct Surface {
    LoadSpec load;
    int index = -1;  // in the scene's loads
    SurfaceFaces faces;
  };
  std::vector<Surface> surfaces_;
  std::vector<LoadSpec> all_loads_;
  LoadsSettle settle_;
  LoadsSettle base_motion_start_{std::numeric_limits<double>::infinity(), -1, false};
  bool changes_gravity_ = false;
};

}  // namespace fdem
