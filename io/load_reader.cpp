#include "io/load_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/csv_fields.hpp"
#include "core/error.hpp"
#include "io/gmsh_reader.hpp"
#include "io/histories_reader.hpp"

namespace fdem {

using scene_yaml::join;
using scene_yaml::Reader;

namespace {

// A path given in the scene, relative to the scene file.
std::string scene_relative(const std::string& given, const std::string& scene_dir) {
  const std::filesystem::path p(given);
  return p.is_absolute() ? p.string()
                         : (std::filesystem::path(scene_dir) / p).lexically_normal().string();
}

}  // namespace

std::vector<int> read_body_list(const Reader& r, const YAML::Node& node, const std::string& path,
                                const std::vector<std::string>& names) {
  r.require_present(node, path, "a list of body names, e.g. [base, wall]");
  if (!node.IsSequence()) r.fail(node, path, "expected a list of body names, e.g. [base, wall]");
  std::vector<int> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string name = r.string(node[i], path);
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      const std::string near = nearest_name(name, names);
      r.fail(node[i], path,
             "no body named '" + name + "'." +
                 (near.empty() ? "" : " Did you mean '" + near + "'?") + " Bodies: " + join(names) +
                 ".");
    }
    out.push_back(static_cast<int>(it - names.begin()));
  }
  return out;
}

RegionSpec read_box_region(const Reader& r, const YAML::Node& region, const std::string& path) {
  r.check_keys(region, path, {"box"}, {"box"});
  r.check_keys(region["box"], path + ".box", {"min", "max"}, {"min", "max"});
  RegionSpec reg;
  reg.min = r.vec3(region["box"]["min"], path + ".box.min");
  reg.max = r.vec3(region["box"]["max"], path + ".box.max");
  for (int k = 0; k < 3; ++k)
    if (reg.max[k] < reg.min[k])
      r.fail(region["box"]["max"], path + ".box.max",
             "each component of max must be at least min's (the box would hold no node)");
  return reg;
}

namespace {

// A unit vector from a non-zero [x, y, z].
Vec3 direction(const Reader& r, const YAML::Node& node, const std::string& path) {
  const Vec3 d = r.vec3(node, path);
  if (!(d.norm() > 0.0)) r.fail(node, path, "a direction must not be [0, 0, 0]");
  return d.normalized();
}

BaseMotionSpec read_base_motion(const Reader& r, const YAML::Node& node, const std::string& path,
                                const std::string& scene_dir) {
  r.check_keys(node, path, {"file", "direction", "scale"}, {"file", "direction"});
  BaseMotionSpec spec;
  const std::filesystem::path p(r.string(node["file"], path + ".file"));
  spec.file = p.is_absolute() ? p.string()
                              : (std::filesystem::path(scene_dir) / p).lexically_normal().string();
  if (!std::filesystem::exists(spec.file))
    r.fail(node["file"], path + ".file",
           "acceleration record '" + spec.file +
               "' does not exist (paths are relative to the scene file; CSV rows: time, "
               "acceleration)");
  spec.direction = direction(r, node["direction"], path + ".direction");
  if (node["scale"]) spec.scale = r.number(node["scale"], path + ".scale");
  return spec;
}

LoadSpec read_tilt(const Reader& r, const YAML::Node& node, const std::string& path) {
  r.check_keys(node, path, {"axis", "rate", "max", "start"}, {"axis", "rate", "max"});
  LoadSpec load;
  load.kind = LoadSpec::Kind::tilt;
  load.tilt.axis = direction(r, node["axis"], path + ".axis");
  const double deg = M_PI / 180.0;
  load.tilt.rate = r.positive(node["rate"], path + ".rate", "tilt rate (degrees/s)") * deg;
  load.tilt.max = r.positive(node["max"], path + ".max", "largest tilt (degrees)") * deg;
  if (load.tilt.max > M_PI)
    r.fail(node["max"], path + ".max", "the largest tilt is in degrees and at most 180");
  if (node["start"])
    load.tilt.start = r.non_negative(node["start"], path + ".start", "start time (s)");
  return load;
}

LoadSpec read_ramp(const Reader& r, const YAML::Node& node, const std::string& path,
                   const std::string& scene_dir) {
  r.check_keys(node, path, {"direction", "rate", "max", "start", "history"}, {"direction"});
  LoadSpec load;
  load.kind = LoadSpec::Kind::ramp;
  load.ramp.direction = direction(r, node["direction"], path + ".direction");
  if (const YAML::Node h = node["history"]) {  // the acceleration (m/s²) as a time history
    for (const char* key : {"rate", "max", "start"})
      if (node[key])
        r.fail(node[key], path + "." + key,
               "give either 'history' (the acceleration in m/s^2) or rate, max and start");
    load.ramp.history = read_time_history(r, h, path + ".history", scene_dir);
    return load;
  }
  for (const char* key : {"rate", "max"})
    if (!node[key])
      r.fail(node, path + "." + key,
             std::string("missing required key '") + key +
                 "' (a ramp needs rate and max, or a 'history' of the acceleration in m/s^2)");
  load.ramp.rate = r.positive(node["rate"], path + ".rate", "acceleration rate (m/s^3)");
  load.ramp.max = r.positive(node["max"], path + ".max", "largest acceleration (m/s^2)");
  if (node["start"])
    load.ramp.start = r.non_negative(node["start"], path + ".start", "start time (s)");
  return load;
}

// Where a load acts: `bodies` or `region` (a box; nodes, or faces with three corners, inside it
// at t = 0).
void read_where(const Reader& r, const YAML::Node& l, const std::string& lp,
                const std::vector<std::string>& body_names, LoadSpec& load) {
  if (l["bodies"] && l["region"]) r.fail(l, lp, "give either 'bodies' or 'region', not both");
  if (l["bodies"]) {
    load.bodies = read_body_list(r, l["bodies"], lp + ".bodies", body_names);
  } else if (const YAML::Node region = l["region"]) {
    load.region = read_box_region(r, region, lp + ".region");
  } else {
    r.fail(l, lp, "a load needs 'bodies' or 'region' to say where it acts");
  }
}

// {pressure: p} or {traction: [tx, ty, tz]} with `follower` (pressure only).
void read_surface(const Reader& r, const YAML::Node& l, const std::string& lp, LoadSpec& load) {
  load.kind = LoadSpec::Kind::surface;
  if (l["pressure"] && l["traction"])
    r.fail(l, lp,
           "give either 'pressure' (Pa, along the inward normal) or 'traction' ([tx, ty, tz] Pa), "
           "not both");
  if (l["velocity"])
    r.fail(l["velocity"], lp + ".velocity",
           "a surface load ('pressure' or 'traction') prescribes no velocity: make it a load of "
           "its own");
  if (const YAML::Node p = l["pressure"]) {
    load.surface.kind = SurfaceLoadSpec::Kind::pressure;
    load.surface.pressure = r.number(p, lp + ".pressure");
    if (const YAML::Node f = l["follower"]) load.surface.follower = r.boolean(f, lp + ".follower");
  } else {
    load.surface.kind = SurfaceLoadSpec::Kind::traction;
    load.surface.traction = r.vec3(l["traction"], lp + ".traction");
    if (l["follower"])
      r.fail(l["follower"], lp + ".follower",
             "'follower' applies to a pressure; a traction keeps its direction and acts on the "
             "reference area");
  }
}

}  // namespace

void read_loads(const Reader& r, const YAML::Node& loads, const std::string& scene_dir,
                const std::vector<std::string>& body_names, Scene& scene) {
  if (!loads.IsSequence()) r.fail(loads, "loads", "expected a list of loads");
  for (std::size_t i = 0; i < loads.size(); ++i) {
    const std::string lp = "loads[" + std::to_string(i) + "]";
    const YAML::Node l = loads[i];
    r.check_keys(l, lp,
                 {"name", "bodies", "region", "velocity", "base_motion", "tilt", "ramp", "pressure",
                  "traction", "follower", "history", "physical"});
    LoadSpec load;
    load.name = read_load_name(r, l, lp, scene.loads);
    if (l["tilt"] || l["ramp"]) {
      const bool tilt = static_cast<bool>(l["tilt"]);
      const std::string key = tilt ? "tilt" : "ramp";
      if (l.size() != 1)
        r.fail(l, lp,
               "a '" + key + "' load changes gravity everywhere: give it alone, as {" + key +
                   ": {...}}");
      scene.loads.push_back(tilt ? read_tilt(r, l["tilt"], lp + ".tilt")
                                 : read_ramp(r, l["ramp"], lp + ".ramp", scene_dir));
      if (tilt) {  // a tilt that turns nothing is a mistake, not a load
        const Vec3& g = scene.gravity;
        if (!(g.norm() > 0.0))
          r.fail(l["tilt"], lp + ".tilt",
                 "a tilt turns the gravity, and the scene's gravity is zero: give gravity");
        if (scene.loads.back().tilt.axis.cross(g).norm() <= 1e-9 * g.norm())
          r.fail(l["tilt"]["axis"], lp + ".tilt.axis",
                 "along the gravity: turning the gravity about it changes nothing; give a "
                 "horizontal axis (e.g. [0, 1, 0] turns gravity [0, 0, -g] towards -x)");
      }
      continue;
    }
    if (const YAML::Node bm = l["base_motion"]) {
      if (!l["bodies"] || l["region"] || l["velocity"] || l["history"])
        r.fail(l, lp,
               "a base motion moves whole bodies: give {bodies: [...], base_motion: {...}} "
               "without 'region', 'velocity' or 'history'");
      load.kind = LoadSpec::Kind::base_motion;
      load.bodies = read_body_list(r, l["bodies"], lp + ".bodies", body_names);
      load.base_motion = read_base_motion(r, bm, lp + ".base_motion", scene_dir);
      scene.loads.push_back(load);
      continue;
    }
    const bool surface = l["pressure"] || l["traction"];
    if (!surface && !l["velocity"])
      r.fail(l, lp + ".velocity",
             "missing required key 'velocity' (or give pressure, traction, base_motion, tilt or "
             "ramp)");
    if (!surface && l["follower"])
      r.fail(l["follower"], lp + ".follower", "'follower' applies to a pressure load only");
    read_where(r, l, lp, body_names, load);
    load.where = l["region"] ? r.location(l["region"], lp + ".region")
                             : r.location(l["bodies"], lp + ".bodies");
    if (const YAML::Node h = l["history"])
      load.history = read_time_history(r, h, lp + ".history", scene_dir);
    if (!surface && l["physical"])
      r.fail(l["physical"], lp + ".physical",
             "'physical' (a Gmsh physical surface) applies to pressure and traction loads only");
    if (surface) {
      read_surface(r, l, lp, load);
      if (const YAML::Node ph = l["physical"]) {
        const std::string pp = lp + ".physical";
        if (!l["bodies"] || load.bodies.size() != 1)
          r.fail(ph, pp,
                 "a physical surface belongs to one body's Gmsh file: give {bodies: [one body], "
                 "physical: NAME}");
        const BodySpec& body = scene.bodies[static_cast<std::size_t>(load.bodies[0])];
        if (body.mesh.kind != MeshSpec::Kind::file)
          r.fail(ph, pp,
                 "body '" + body.name +
                     "' is not meshed from a Gmsh file; physical surfaces need mesh: {file: "
                     "part.msh}");
        load.surface.physical = r.string(ph, pp);
        try {
          load.surface.triangles = read_gmsh_surface(body.mesh.file, load.surface.physical);
        } catch (const InputError& e) {
          r.fail(ph, pp,
                 std::string(e.what()) +
                     " (physical surfaces are read from the .msh file, not a prepared model "
                     "file)");
        }
      }
      scene.loads.push_back(load);
      continue;
    }
    const YAML::Node v = l["velocity"];
    if (!v.IsSequence() || v.size() != 3)
      r.fail(v, lp + ".velocity", "expected [vx, vy, vz] in m/s (null leaves a component free)");
    load.dof_mask = 0;
    for (int k = 0; k < 3; ++k) {
      if (v[k].IsNull()) continue;
      load.velocity[k] = r.number(v[k], lp + ".velocity");
      load.dof_mask |= 1u << k;
    }
    scene.loads.push_back(load);
  }
}

TimeHistory read_history_file(const std::string& path) {
  csv_fields::TimeValueRows rows =
      csv_fields::read_time_value_rows(path, "value", "a time history");
  TimeHistory h = TimeHistory::table(std::move(rows.time), std::move(rows.value));
  h.source = path;
  return h;
}

TimeHistory read_time_history(const Reader& r, const YAML::Node& node, const std::string& path,
                              const std::string& scene_dir) {
  const char* forms =
      "a number, {table: [[t0, v0], [t1, v1], ...]}, {file: history.csv} or {smooth_step: "
      "{start, end, from, to, shape}}";
  r.require_present(node, path, forms);
  if (node.IsScalar()) {
    TimeHistory h = TimeHistory::constant_value(r.number(node, path));
    h.source = r.location(node, path);
    return h;
  }
  if (!node.IsMap() || node.size() != 1)
    r.fail(node, path, std::string("expected one of: ") + forms);
  r.check_keys(node, path, {"table", "file", "smooth_step"});
  if (const YAML::Node table = node["table"]) {
    const std::string tp = path + ".table";
    if (!table.IsSequence() || table.size() < 2)
      r.fail(table, tp, "expected a list of at least two [time, value] pairs, times increasing");
    std::vector<double> times, values;
    for (std::size_t i = 0; i < table.size(); ++i) {
      const std::string ip = tp + "[" + std::to_string(i) + "]";
      if (!table[i].IsSequence() || table[i].size() != 2)
        r.fail(table[i], ip, "expected a pair [time, value] (s, value)");
      const double t = r.non_negative(table[i][0], ip + "[0]", "a time (s)");
      if (!times.empty() && !(t > times.back()))
        r.fail(table[i][0], ip + "[0]",
               Reader::format(t) + " s does not increase (previous row: " +
                   Reader::format(times.back()) + " s); times must increase");
      times.push_back(t);
      values.push_back(r.number(table[i][1], ip + "[1]"));
    }
    TimeHistory h = TimeHistory::table(std::move(times), std::move(values));
    h.source = r.location(table, tp);
    return h;
  }
  if (const YAML::Node file = node["file"]) {
    const std::string resolved = scene_relative(r.string(file, path + ".file"), scene_dir);
    if (!std::filesystem::exists(resolved))
      r.fail(file, path + ".file",
             "time history '" + resolved +
                 "' does not exist (paths are relative to the scene file; CSV rows: time, value)");
    return read_history_file(resolved);
  }
  const YAML::Node step = node["smooth_step"];
  const std::string sp = path + ".smooth_step";
  r.check_keys(step, sp, {"start", "end", "from", "to", "shape"}, {"end"});
  const double start =
      step["start"] ? r.non_negative(step["start"], sp + ".start", "the start time (s)") : 0.0;
  const double end = r.number(step["end"], sp + ".end");
  if (!(end > start))
    r.fail(step["end"], sp + ".end",
           Reader::format(end) + " s must be after start (" + Reader::format(start) + " s)");
  const double from = step["from"] ? r.number(step["from"], sp + ".from") : 0.0;
  const double to = step["to"] ? r.number(step["to"], sp + ".to") : 1.0;
  TimeHistory::Shape shape = TimeHistory::Shape::quintic;
  if (step["shape"]) {
    const std::string s = r.choice(step["shape"], sp + ".shape", {"cubic", "quintic", "sine"});
    shape = s == "cubic"  ? TimeHistory::Shape::cubic
            : s == "sine" ? TimeHistory::Shape::sine
                          : TimeHistory::Shape::quintic;
  }
  TimeHistory h = TimeHistory::smooth_step(start, end, from, to, shape);
  h.source = r.location(step, sp);
  return h;
}

}  // namespace fdem
