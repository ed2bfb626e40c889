#include "drivers/loads.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/csv_fields.hpp"
#include "core/error.hpp"
#include "core/history_sums.hpp"

namespace fdem {

void read_acceleration_record(const std::string& path, BaseMotionSpec& spec) {
  csv_fields::TimeValueRows rows =
      csv_fields::read_time_value_rows(path, "acceleration", "an acceleration record");
  spec.time = std::move(rows.time);
  spec.acceleration = std::move(rows.value);
}

double base_velocity(const BaseMotionSpec& spec, double t) {
  const auto& T = spec.time;
  const auto& A = spec.acceleration;
  if (T.empty() || t <= T.front()) return 0.0;
  double v = 0.0;  // ∫ a dt in record units
  for (std::size_t i = 0; i + 1 < T.size(); ++i) {
    const double h = T[i + 1] - T[i];
    if (t < T[i + 1]) {
      const double s = t - T[i];
      v += A[i] * s + 0.5 * (A[i + 1] - A[i]) * s * s / h;
      return spec.scale * v;
    }
    v += 0.5 * (A[i] + A[i + 1]) * h;
  }
  return spec.scale * v;
}

double tilt_angle(const TiltSpec& tilt, double t) {
  return std::clamp(tilt.rate * (t - tilt.start), 0.0, tilt.max);
}

double ramp_acceleration(const RampSpec& ramp, double t) {
  if (ramp.history) return (*ramp.history)(t);
  return std::clamp(ramp.rate * (t - ramp.start), 0.0, ramp.max);
}

LoadsSettle later(const LoadsSettle& a, const LoadsSettle& b) {
  return b.time > a.time ? b : a;
}

LoadsSettle loads_settle(const std::vector<LoadSpec>& loads) {
  LoadsSettle out;
  for (std::size_t i = 0; i < loads.size(); ++i) {
    const LoadSpec& load = loads[i];
    double until = 0.0;  // s: this load is constant from then on
    bool moving = false;
    switch (load.kind) {
      case LoadSpec::Kind::velocity:
        if (load.velocity.isZero(0.0)) break;  // a support
        moving = load.history.final_value() != 0.0;
        until = moving ? HUGE_VAL : load.history.last_change();
        break;
      case LoadSpec::Kind::base_motion:  // after its record the ground moves uniformly
        until = load.base_motion.time.empty() ? 0.0 : load.base_motion.time.back();
        break;
      case LoadSpec::Kind::tilt:
        if (load.tilt.rate > 0.0 && load.tilt.max > 0.0)
          until = load.tilt.start + load.tilt.max / load.tilt.rate;
        break;
      case LoadSpec::Kind::ramp:
        if (load.ramp.history)
          until = load.ramp.history->last_change();
        else if (load.ramp.rate > 0.0 && load.ramp.max > 0.0)
          until = load.ramp.start + load.ramp.max / load.ramp.rate;
        break;
      case LoadSpec::Kind::surface:
        until = load.history.last_change();
        break;
    }
    out = later(out, {until, static_cast<int>(i), moving});
  }
  return out;
}

std::string load_label(const Scene& scene, int index) {
  const std::string& name = scene.loads[static_cast<std::size_t>(index)].name;
  return name.empty() ? "loads[" + std::to_string(index) + "]" : "load '" + name + "'";
}

std::string describe_loads_settle(const Scene& scene, const LoadsSettle& settle) {
  if (settle.load < 0) return "no load changes";
  const LoadSpec& load = scene.loads[static_cast<std::size_t>(settle.load)];
  static const char* const kinds[] = {"a prescribed velocity", "a base motion", "a tilt", "a ramp",
                                      "a surface load"};
  std::ostringstream out;
  out << load_label(scene, settle.load) << ", " << kinds[static_cast<int>(load.kind)] << ", ";
  if (settle.moving)
    out << "keeps its boundary moving to the end";
  else
    out << "changes until t = " << settle.time << " s";
  return out.str();
}

Vec3 gravity_at(const Scene& scene, double t) {
  Vec3 g = scene.gravity;
  for (const LoadSpec& load : scene.loads)
    if (load.kind == LoadSpec::Kind::tilt)
      g = Eigen::AngleAxisd(tilt_angle(load.tilt, t), load.tilt.axis) * g;
  for (const LoadSpec& load : scene.loads)
    if (load.kind == LoadSpec::Kind::ramp)
      g += ramp_acceleration(load.ramp, t) * load.ramp.direction;
  return g;
}

LoadSchedule::LoadSchedule(const Scene& scene, const Model& model) {
  scene_.gravity = scene.gravity;
  for (const LoadSpec& load : scene.loads) {
    if (load.kind == LoadSpec::Kind::tilt || load.kind == LoadSpec::Kind::ramp) {
      scene_.loads.push_back(load);
      changes_gravity_ = true;
    } else if (load.kind == LoadSpec::Kind::base_motion) {
      Base base{load.base_motion, load.bodies, {}};
      if (base.motion.time.empty()) read_acceleration_record(base.motion.file, base.motion);
      if (base.motion.time.size() != base.motion.acceleration.size() || base.motion.time.size() < 2)
        throw InputError(scene.source_path +
                         ": a base motion needs at least two samples of time and acceleration");
      const int index = static_cast<int>(&load - scene.loads.data());
      settle_ = later(settle_, {base.motion.time.back(), index, false});
      // Linear between samples, zero before the first: the ground moves from the sample before
      // the first non-zero acceleration on.
      const std::vector<double>& a = base.motion.acceleration;
      const auto first = std::find_if(a.begin(), a.end(), [](double x) { return x != 0.0; });
      if (first != a.end()) {
        const std::size_t k = static_cast<std::size_t>(first - a.begin());
        const double start = base.motion.time[k > 0 ? k - 1 : 0];
        if (start < base_motion_start_.time) base_motion_start_ = {start, index, false};
      }
      bases_.push_back(std::move(base));
    } else if (load.kind == LoadSpec::Kind::surface) {
      surfaces_.push_back({load, static_cast<int>(&load - scene.loads.data()), {}});
    } else if (load.kind == LoadSpec::Kind::velocity && load.history.varies()) {
      varying_.push_back({load, static_cast<int>(&load - scene.loads.data()), {}, {}});
    }
  }
  all_loads_ = scene.loads;
  settle_ = later(settle_, loads_settle(scene.loads));
  rebind(model);
}

void LoadSchedule::rebind(const Model& model) {
  FDEM_VERIFY((bases_.empty() && varying_.empty()) || model.nodes.has_prescribed_velocity,
              "velocity loads need the nodes' prescribed velocities");
  for (Surface& surface : surfaces_) surface.faces = select_surface_faces(model, surface.load);
  if (!varying_.empty()) {
    // Which load sets each prescribed component: the last in scene order that holds the node, as
    // apply_constraints sets them (fixed bodies first).
    std::vector<int> setter(3 * static_cast<std::size_t>(model.nodes.size()), -1);
    for (int l = 0; l < static_cast<int>(all_loads_.size()); ++l) {
      const LoadSpec& load = all_loads_[static_cast<std::size_t>(l)];
      if (!load.prescribes_velocity()) continue;
      for (LocalIndex n = 0; n < model.nodes.size(); ++n)
        if (load_holds_node(load, model, n))
          for (int k = 0; k < 3; ++k)
            if (load.dof_mask & (1u << k)) setter[3 * static_cast<std::size_t>(n) + k] = l;
    }
    for (Varying& v : varying_) {
      v.nodes.clear();
      v.masks.clear();
      for (LocalIndex n = 0; n < model.nodes.size(); ++n) {
        std::uint8_t mask = 0;
        for (int k = 0; k < 3; ++k)
          if (setter[3 * static_cast<std::size_t>(n) + k] == v.index) mask |= 1u << k;
        if (mask) {
          v.nodes.push_back(n);
          v.masks.push_back(mask);
        }
      }
    }
  }
  for (Base& base : bases_) {
    base.nodes.clear();
    for (LocalIndex n = 0; n < model.nodes.size(); ++n) {
      const std::int32_t body = model.pieces.body_of(model.nodes.piece[n]);
      if (std::find(base.bodies.begin(), base.bodies.end(), body) != base.bodies.end())
        base.nodes.push_back(n);
    }
  }
}

void LoadSchedule::apply(double t, double dt, Model& model) const {
  if (changes_gravity_) model.gravity = gravity_at(scene_, t);
  for (const Base& base : bases_) {
    const Vec3 v = base_velocity(base.motion, t + 0.5 * dt) * base.motion.direction;
    for (LocalIndex n : base.nodes) vec3_at(model.nodes.prescribed_velocity.data(), n) = v;
  }
  for (const Varying& varying : varying_) {
    const Vec3 v = varying.load.history(t + 0.5 * dt) * varying.load.velocity;
    for (std::size_t i = 0; i < varying.nodes.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (varying.masks[i] & (1u << k))
          model.nodes.prescribed_velocity[3 * static_cast<std::size_t>(varying.nodes[i]) + k] =
              v[k];
  }
}

void LoadSchedule::add_surface_forces(double t, Model& model) {
  for (Surface& surface : surfaces_)
    fdem::add_surface_forces(surface.load.surface, surface.load.history(t), surface.faces,
                             model.nodes);
}

double LoadSchedule::surface_power(const Model& model) const {
  double power = 0.0;
  for (const Surface& surface : surfaces_) power += fdem::surface_power(surface.faces, model.nodes);
  return power;
}

double LoadSchedule::surface_force_magnitude() const {
  double sum = 0.0;
  for (const Surface& surface : surfaces_) sum += fdem::surface_force_magnitude(surface.faces);
  return sum;
}

std::vector<std::pair<int, std::int64_t>> LoadSchedule::surface_face_counts() const {
  std::vector<std::pair<int, std::int64_t>> counts;
  for (const Surface& surface : surfaces_) {
    std::int64_t owned = 0;
    for (const std::uint8_t o : surface.faces.owned) owned += o;
    counts.emplace_back(surface.index, owned);
  }
  return counts;
}

}  // namespace fdem
