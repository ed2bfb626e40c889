#include "drivers/restart_check.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"

namespace fdem {

namespace {

// Checkpoint value names may not hold '/' (HDF5 paths).
std::string key_name(const std::string& name) {
  std::string out = name;
  std::replace(out.begin(), out.end(), '/', '_');
  return out;
}

void add_vec3(std::vector<std::pair<std::string, double>>& values, const std::string& key,
              const Vec3& v) {
  values.emplace_back(key + ".x", v.x());
  values.emplace_back(key + ".y", v.y());
  values.emplace_back(key + ".z", v.z());
}

void add_material(std::vector<std::pair<std::string, double>>& values, const MaterialSpec& m) {
  const std::string key = "materials." + key_name(m.name);
  values.emplace_back(key + ".density", m.density);
  values.emplace_back(key + ".elastic.young", m.elastic.young);
  values.emplace_back(key + ".elastic.poisson", m.elastic.poisson);
  values.emplace_back(key + ".elastic.model", m.elastic.model == ElasticModel::neo_hookean ? 0 : 1);
  values.emplace_back(key + ".damping", m.damping);
  values.emplace_back(key + ".contact.penalty", m.contact.auto_penalty ? -1.0 : m.contact.penalty);
  values.emplace_back(key + ".contact.friction", m.contact.friction);
  values.emplace_back(key + ".contact.damping", m.contact.damping);
  if (m.fracture) {
    values.emplace_back(key + ".fracture.tensile_strength", m.fracture->tensile_strength);
    values.emplace_back(key + ".fracture.cohesion", m.fracture->cohesion);
    values.emplace_back(key + ".fracture.friction_angle", m.fracture->friction_angle_deg);
    values.emplace_back(key + ".fracture.energy_I", m.fracture->energy_I);
    values.emplace_back(key + ".fracture.energy_II", m.fracture->energy_II);
    // Listed only when set, so that a checkpoint of a scene without them restarts without a
    // warning about keys it never had.
    if (m.fracture->normal_penalty > 0.0)
      values.emplace_back(key + ".fracture.penalty.normal", m.fracture->normal_penalty);
    if (m.fracture->tangential_penalty > 0.0)
      values.emplace_back(key + ".fracture.penalty.tangential", m.fracture->tangential_penalty);
    const StrengthDistributionSpec& d = m.fracture->strength_distribution;
    if (d.type != StrengthDistributionSpec::Type::none) {
      const std::string dk = key + ".fracture.strength_distribution";
      values.emplace_back(dk + ".type", static_cast<double>(d.type));
      values.emplace_back(dk + ".modulus", d.modulus);
      values.emplace_back(dk + ".cov", d.cov);
      values.emplace_back(dk + ".seed", static_cast<double>(d.seed));  // < 2^53: exact
    }
  }
}

// A time history by its kind and numbers (a table by its rows).
void add_history(std::vector<std::pair<std::string, double>>& values, const std::string& key,
                 const TimeHistory& h) {
  values.emplace_back(key + ".kind", static_cast<double>(h.kind));
  switch (h.kind) {
    case TimeHistory::Kind::constant:
      values.emplace_back(key, h.value);
      break;
    case TimeHistory::Kind::table: {  // a few numbers that change with any row (a table may have
                                      // thousands of rows)
      double sum_t = 0, sum_v = 0, sum_tv = 0;
      for (std::size_t i = 0; i < h.times.size(); ++i) {
        sum_t += h.times[i];
        sum_v += h.values[i];
        sum_tv += (1.0 + h.times[i]) * h.values[i];
      }
      values.emplace_back(key + ".table.rows", static_cast<double>(h.times.size()));
      values.emplace_back(key + ".table.sum_of_times", sum_t);
      values.emplace_back(key + ".table.sum_of_values", sum_v);
      values.emplace_back(key + ".table.weighted_sum", sum_tv);
      break;
    }
    case TimeHistory::Kind::smooth_step:
      values.emplace_back(key + ".smooth_step.start", h.start);
      values.emplace_back(key + ".smooth_step.end", h.end);
      values.emplace_back(key + ".smooth_step.from", h.from);
      values.emplace_back(key + ".smooth_step.to", h.to);
      values.emplace_back(key + ".smooth_step.shape", static_cast<double>(h.shape));
      break;
  }
}

void add_load(std::vector<std::pair<std::string, double>>& values, const LoadSpec& load,
              std::size_t index) {
  const std::string key = "loads[" + std::to_string(index) + "]";
  values.emplace_back(key + ".kind", static_cast<double>(load.kind));
  switch (load.kind) {
    case LoadSpec::Kind::velocity:
      values.emplace_back(key + ".prescribed_components", load.dof_mask);
      add_vec3(values, key + ".velocity", load.velocity);
      break;
    case LoadSpec::Kind::base_motion:
      values.emplace_back(key + ".base_motion.scale", load.base_motion.scale);
      add_vec3(values, key + ".base_motion.direction", load.base_motion.direction);
      break;
    case LoadSpec::Kind::tilt:
      values.emplace_back(key + ".tilt.rate", load.tilt.rate);
      values.emplace_back(key + ".tilt.max", load.tilt.max);
      values.emplace_back(key + ".tilt.start", load.tilt.start);
      break;
    case LoadSpec::Kind::ramp:
      values.emplace_back(key + ".ramp.rate", load.ramp.rate);
      values.emplace_back(key + ".ramp.max", load.ramp.max);
      values.emplace_back(key + ".ramp.start", load.ramp.start);
      if (load.ramp.history) add_history(values, key + ".ramp.history", *load.ramp.history);
      break;
    case LoadSpec::Kind::surface:
      values.emplace_back(key + ".pressure", load.surface.pressure);
      add_vec3(values, key + ".traction", load.surface.traction);
      values.emplace_back(key + ".follower", load.surface.follower);
      values.emplace_back(key + ".physical.triangles",
                          static_cast<double>(load.surface.triangles.size() / 9));
      break;
  }
  if (load.kind == LoadSpec::Kind::velocity || load.kind == LoadSpec::Kind::surface)
    add_history(values, key + ".history", load.history);
}

// What a changed key does on a restart: refused, or a warning saying what happens.
enum class Effect { refused, ignored, applied };

Effect effect_of(const std::string& key) {
  const auto ends_with = [&](const std::string& tail) {
    return key.size() >= tail.size() &&
           key.compare(key.size() - tail.size(), tail.size(), tail) == 0;
  };
  // The masses, the stored strain energy and the ledger depend on these: the stored state would
  // not be a state of the new scene.
  if (key.rfind("materials.", 0) == 0 &&
      (ends_with(".density") || ends_with(".elastic.young") || ends_with(".elastic.poisson") ||
       ends_with(".elastic.model")))
    return Effect::refused;
  if (key.rfind("bodies.", 0) == 0 && ends_with(".material")) return Effect::refused;
  // The stored strain energy and the state's equilibrium include the initial stress.
  if (key.rfind("initial_stress[", 0) == 0) return Effect::refused;
  // Initial conditions and the step: the checkpoint's velocities and step continue.
  if (key.find(".velocity.") != std::string::npos && key.rfind("bodies.", 0) == 0)
    return Effect::ignored;
  if (key.find(".angular_velocity.") != std::string::npos) return Effect::ignored;
  if (key.rfind("time.", 0) == 0) return Effect::ignored;
  return Effect::applied;
}

std::string format(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

}  // namespace

std::vector<std::pair<std::string, double>> restart_scene_values(const Scene& scene) {
  std::vector<std::pair<std::string, double>> values;
  values.emplace_back("time.step", scene.time.auto_step ? -1.0 : scene.time.step);
  values.emplace_back("time.safety", scene.time.safety);
  add_vec3(values, "gravity", scene.gravity);
  for (const MaterialSpec& m : scene.materials) add_material(values, m);
  // The contact law the run uses (contact.formulation, auto resolved), listed only under corner
  // contact, so that a checkpoint of potential contact restarts without a key it never had.
  if (uses_corner_contact(scene)) values.emplace_back("contact.corners", 1.0);
  // The quasi-static mode, listed only while on (a dynamic run's checkpoint has no such key).
  if (const QuasiStaticSpec& q = scene.quasi_static; q.enabled()) {
    values.emplace_back("quasi_static.damping", q.kinetic() ? 1.0 : 0.0);  // 0 local, 1 kinetic
    values.emplace_back("quasi_static.local_damping", q.local_damping);
    values.emplace_back("quasi_static.until", std::isfinite(q.until) ? q.until : -1.0);
    values.emplace_back("quasi_static.equilibrium_ratio", q.equilibrium_ratio);
  }
  for (const BodySpec& body : scene.bodies) {
    const std::string key = "bodies." + key_name(body.name);
    values.emplace_back(key + ".material", body.material);
    values.emplace_back(key + ".fixed", body.fixed ? 1.0 : 0.0);
    add_vec3(values, key + ".velocity", body.velocity);
    add_vec3(values, key + ".angular_velocity", body.angular_velocity);
  }
  for (std::size_t i = 0; i < scene.loads.size(); ++i) add_load(values, scene.loads[i], i);
  for (std::size_t i = 0; i < scene.absorbing.size(); ++i) {
    const std::string key = "absorbing[" + std::to_string(i) + "].region.box";
    add_vec3(values, key + ".min", scene.absorbing[i].region.min);
    add_vec3(values, key + ".max", scene.absorbing[i].region.max);
  }
  for (std::size_t i = 0; i < scene.initial_stress.size(); ++i) {
    const InitialStressSpec& s = scene.initial_stress[i];
    const std::string key = "initial_stress[" + std::to_string(i) + "]";
    values.emplace_back(key + ".kind", static_cast<double>(s.kind));
    for (int k = 0; k < 6; ++k)
      values.emplace_back(key + ".uniform." + std::to_string(k), s.stress[k]);
    values.emplace_back(key + ".geostatic.surface", s.surface);
    values.emplace_back(key + ".geostatic.k0", s.k0);
  }
  return values;
}

std::vector<std::string> compare_restart_scene(const Scene& scene,
                                               const std::map<std::string, double>& stored,
                                               const std::string& checkpoint) {
  std::map<std::string, double> now;
  for (const auto& [key, value] : restart_scene_values(scene)) now[key] = value;
  std::vector<std::string> refused, warnings;
  const auto report = [&](const std::string& key, const std::string& change) {
    switch (effect_of(key)) {
      case Effect::refused:
        refused.push_back(key + " " + change);
        break;
      case Effect::ignored:
        warnings.push_back(key + " " + change +
                           " is ignored: the checkpoint's state (velocities, time step) continues");
        break;
      case Effect::applied:
        warnings.push_back(key + " " + change + " applies from the checkpoint's time on");
        break;
    }
  };
  for (const auto& [key, value] : now) {
    const auto it = stored.find(key);
    if (it == stored.end())
      report(key, "(new, " + format(value) + ")");
    else if (it->second != value)
      report(key, "changed from " + format(it->second) + " to " + format(value));
  }
  for (const auto& [key, value] : stored)
    if (!now.count(key)) report(key, "(" + format(value) + " in the checkpoint) was removed");
  if (!refused.empty()) {
    std::string msg = "checkpoint '" + checkpoint +
                      "' holds a state of other materials than this scene's; a restart cannot "
                      "change: ";
    for (std::size_t i = 0; i < refused.size(); ++i) msg += (i ? "; " : "") + refused[i];
    throw InputError(msg + ". Restore these values, or start the run afresh.");
  }
  return warnings;
}

}  // namespace fdem
