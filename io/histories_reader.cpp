#include "io/histories_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace fdem {

using scene_yaml::join;
using scene_yaml::Reader;

namespace {

// A name that goes into a histories.csv column header: no separator, quote or blank.
bool column_safe(const std::string& name) {
  return !name.empty() && std::none_of(name.begin(), name.end(), [](char c) {
    return c == ',' || c == '"' || std::isspace(static_cast<unsigned char>(c)) ||
           std::iscntrl(static_cast<unsigned char>(c));
  });
}

const char* column_rule = "a name in histories.csv column headers has no comma, quote or blank";

// "all" or a list of names from `names`; returns their indices, in the order given.
std::vector<int> read_selection(const Reader& r, const YAML::Node& node, const std::string& path,
                                const std::vector<std::string>& names, const std::string& what) {
  std::vector<int> out;
  r.require_present(node, path, "'all' or a list of names");
  if (node.IsScalar() && node.Scalar() == "all") {
    for (std::size_t i = 0; i < names.size(); ++i) out.push_back(static_cast<int>(i));
    return out;
  }
  if (!node.IsSequence())
    r.fail(
        node, path,
        "expected 'all' or a list of " + what + " names" +
            (names.empty() ? std::string(" (the scene has none)") : ", e.g. [" + names[0] + "]"));
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    const std::string name = r.string(node[i], item);
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      const std::string near = nearest_name(name, names);
      r.fail(node[i], item,
             "no " + what + " named '" + name + "'." +
                 (near.empty() ? "" : " Did you mean '" + near + "'?") + " Valid " + what +
                 " names: " + (names.empty() ? std::string("none") : join(names)) + ".");
    }
    const int index = static_cast<int>(it - names.begin());
    if (std::find(out.begin(), out.end(), index) != out.end())
      r.fail(node[i], item, what + " '" + name + "' is listed twice");
    out.push_back(index);
  }
  return out;
}

}  // namespace

std::string read_load_name(const Reader& r, const YAML::Node& l, const std::string& path,
                           const std::vector<LoadSpec>& earlier) {
  const std::string name =
      l["name"] ? r.string(l["name"], path + ".name") : "load" + std::to_string(earlier.size());
  if (l["name"] && !column_safe(name))
    r.fail(l["name"], path + ".name", "'" + name + "': " + column_rule);
  for (const LoadSpec& other : earlier)
    if (other.name == name)
      r.fail(l["name"] ? l["name"] : l, path + ".name",
             "load name '" + name + "' is used twice; names must be unique");
  return name;
}

HistoriesSpec read_histories(const Reader& r, const YAML::Node& node, const std::string& path,
                             const Scene& scene, const std::vector<std::string>& body_names) {
  r.check_keys(node, path, {"every", "loads", "bodies", "monitors"});
  HistoriesSpec h;
  h.enabled = true;
  if (node["every"]) {
    h.every = r.non_negative(node["every"], path + ".every", "history row interval (s)");
    const double shortest = 1e-12 * scene.time.end;  // as the other intervals (check_intervals)
    if (h.every > 0.0 && h.every < shortest)
      r.fail(node["every"], path + ".every",
             Reader::format(h.every) + " s cannot advance time: it is below 1e-12 x time.end. " +
                 "Use 0 (every step) or at least " + Reader::format(shortest) + " s.");
  }
  // Loads that hold nodes: prescribed velocities and base motions (not tilts or ramps).
  std::vector<std::string> load_names;
  std::vector<int> load_index;
  for (std::size_t i = 0; i < scene.loads.size(); ++i) {
    const LoadSpec::Kind kind = scene.loads[i].kind;
    if (kind != LoadSpec::Kind::velocity && kind != LoadSpec::Kind::base_motion) continue;
    load_names.push_back(scene.loads[i].name);
    load_index.push_back(static_cast<int>(i));
  }
  if (const YAML::Node loads = node["loads"]) {
    for (int k :
         read_selection(r, loads, path + ".loads", load_names, "velocity or base-motion load"))
      h.loads.push_back(load_index[static_cast<std::size_t>(k)]);
  } else {
    h.loads = load_index;  // default: every load that holds nodes
  }
  if (const YAML::Node bodies = node["bodies"]) {
    h.bodies = read_selection(r, bodies, path + ".bodies", body_names, "body");
    for (std::size_t i = 0; i < h.bodies.size(); ++i)
      if (!column_safe(body_names[static_cast<std::size_t>(h.bodies[i])]))
        r.fail(bodies.IsSequence() ? bodies[i] : bodies, path + ".bodies",
               "body '" + body_names[static_cast<std::size_t>(h.bodies[i])] +
                   "' cannot be recorded: " + column_rule + "; rename it");
  }
  if (const YAML::Node monitors = node["monitors"]) {
    if (!monitors.IsSequence())
      r.fail(monitors, path + ".monitors",
             "expected a list of monitor points, e.g. [{name: centre, point: [0, 0, 0]}]");
    for (std::size_t i = 0; i < monitors.size(); ++i) {
      const std::string mp = path + ".monitors[" + std::to_string(i) + "]";
      const YAML::Node m = monitors[i];
      r.check_keys(m, mp, {"name", "point", "stop_displacement"}, {"point"});
      MonitorSpec spec;
      spec.name = m["name"] ? r.string(m["name"], mp + ".name") : "monitor" + std::to_string(i);
      if (!column_safe(spec.name))
        r.fail(m["name"], mp + ".name", "'" + spec.name + "': " + column_rule);
      for (const MonitorSpec& other : h.monitors)
        if (other.name == spec.name)
          r.fail(m["name"], mp + ".name",
                 "monitor name '" + spec.name + "' is used twice; names must be unique");
      spec.point = r.vec3(m["point"], mp + ".point");
      spec.where = r.location(m["point"], mp + ".point");
      if (m["stop_displacement"]) {
        spec.stop_displacement = r.number(m["stop_displacement"], mp + ".stop_displacement");
        if (!(spec.stop_displacement > 0.0) || !std::isfinite(spec.stop_displacement))
          r.fail(m["stop_displacement"], mp + ".stop_displacement",
                 "must be a positive distance in m: the run ends once the monitor's point has "
                 "moved this far (checked at each row of histories.csv)");
      }
      h.monitors.push_back(spec);
    }
  }
  if (h.loads.empty() && h.bodies.empty() && h.monitors.empty())
    r.fail(node, path,
           "nothing to record: " +
               std::string(load_names.empty() ? "the scene has no velocity or base-motion load; "
                                              : "") +
               "list loads, bodies or monitors");
  return h;
}

}  // namespace fdem
