#include "io/scene_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include "core/error.hpp"

namespace fdem {

std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] =
            std::min({row[j] + 1, row[j - 1] + 1,
                      diagonal + (std::tolower(a[i - 1]) == std::tolower(b[j - 1]) ? 0u : 1u)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const auto& c : candidates) {
    const std::size_t d = distance(word, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  const std::size_t limit = std::max<std::size_t>(2, word.size() / 3);
  return best_distance <= limit ? best : "";
}

namespace {

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
  return s;
}

// Reads one YAML document with positions; every accessor knows its key path for messages.
class Reader {
 public:
  // overridden: (key path as the reader spells it, "--set" assignment) for each override, so
  // errors in overridden values point at the override instead of a line of the file.
  Reader(std::string file, std::vector<std::pair<std::string, std::string>> overridden)
      : file_(std::move(file)), overridden_(std::move(overridden)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& path,
                         const std::string& what) const {
    std::ostringstream msg;
    msg << file_;
    const std::string* assignment = nullptr;
    for (const auto& [prefix, set] : overridden_)
      if (path == prefix || path.rfind(prefix + ".", 0) == 0 || path.rfind(prefix + "[", 0) == 0)
        assignment = &set;
    const YAML::Mark mark = at.IsDefined() ? at.Mark() : YAML::Mark::null_mark();
    // A key that only an override created has no place in the file either.
    if (!assignment && mark.line < 0 && !path.empty())
      for (const auto& [prefix, set] : overridden_)
        if (prefix.rfind(path + ".", 0) == 0 || prefix.rfind(path + "[", 0) == 0) assignment = &set;
    if (assignment)
      msg << ": --set " << *assignment;
    else if (mark.line >= 0)
      msg << ":" << mark.line + 1 << ":" << mark.column + 1;
    msg << ": " << (path.empty() ? std::string("(top level)") : path) << ": " << what;
    throw InputError(msg.str());
  }

  // The text of a mapping key (keys must be plain scalars).
  std::string key_name(const YAML::Node& key, const std::string& path) const {
    if (!key.IsScalar()) fail(key, path, "a key must be a plain name, not a list or a mapping");
    return key.Scalar();
  }

  // Checks a mapping has only allowed keys and has every required key.
  void check_keys(const YAML::Node& node, const std::string& path,
                  const std::vector<std::string>& allowed,
                  const std::vector<std::string>& required = {}) const {
    if (!node.IsMap())
      fail(node, path, "expected a mapping (key: value pairs) with keys " + join(allowed));
    std::vector<std::string> seen;
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = key_name(it->first, path);
      // YAML forbids repeated keys; yaml-cpp would silently use the first one.
      if (std::find(seen.begin(), seen.end(), key) != seen.end())
        fail(it->first, child(path, key), "key '" + key + "' is given twice in this mapping");
      seen.push_back(key);
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        const std::string near = nearest_name(key, allowed);
        fail(it->first, child(path, key),
             "unknown key '" + key + "'." + (near.empty() ? "" : " Did you mean '" + near + "'?") +
                 " Valid keys here: " + join(allowed) + ".");
      }
    }
    for (const auto& key : required)
      if (!node[key]) fail(node, child(path, key), "missing required key '" + key + "'");
  }

  static std::string child(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  double number(const YAML::Node& node, const std::string& path) const {
    if (!node.IsScalar()) fail(node, path, "expected a number");
    try {
      const double value = node.as<double>();
      if (!std::isfinite(value)) fail(node, path, "expected a finite number");
      return value;
    } catch (const YAML::Exception&) {
      fail(node, path, "expected a number, got '" + node.Scalar() + "'");
    }
  }

  double positive(const YAML::Node& node, const std::string& path, const std::string& what) const {
    const double value = number(node, path);
    if (!(value > 0.0))
      fail(node, path, format(value) + " is impossible: " + what + " must be > 0");
    return value;
  }

  double non_negative(const YAML::Node& node, const std::string& path,
                      const std::string& what) const {
    const double value = number(node, path);
    if (value < 0.0) fail(node, path, format(value) + " is impossible: " + what + " must be >= 0");
    return value;
  }

  int integer(const YAML::Node& node, const std::string& path) const {
    if (!node.IsScalar()) fail(node, path, "expected an integer");
    try {
      return node.as<int>();
    } catch (const YAML::Exception&) {
      fail(node, path, "expected an integer, got '" + node.Scalar() + "'");
    }
  }

  bool boolean(const YAML::Node& node, const std::string& path) const {
    if (!node.IsScalar()) fail(node, path, "expected true or false");
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(node, path, "expected true or false, got '" + node.Scalar() + "'");
    }
  }

  std::string string(const YAML::Node& node, const std::string& path) const {
    if (!node.IsScalar()) fail(node, path, "expected a text value");
    return node.Scalar();
  }

  std::string choice(const YAML::Node& node, const std::string& path,
                     const std::vector<std::string>& valid) const {
    const std::string value = string(node, path);
    if (std::find(valid.begin(), valid.end(), value) == valid.end()) {
      const std::string near = nearest_name(value, valid);
      fail(node, path,
           "'" + value + "' is not valid." + (near.empty() ? "" : " Did you mean '" + near + "'?") +
               " Valid values: " + join(valid) + ".");
    }
    return value;
  }

  Vec3 vec3(const YAML::Node& node, const std::string& path) const {
    if (!node.IsSequence() || node.size() != 3)
      fail(node, path, "expected three numbers [x, y, z]");
    return {number(node[0], path + "[0]"), number(node[1], path + "[1]"),
            number(node[2], path + "[2]")};
  }

  // "auto" or a number.
  bool is_auto(const YAML::Node& node) const { return node.IsScalar() && node.Scalar() == "auto"; }

  static std::string format(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::vector<std::pair<std::string, std::string>> overridden_;
};

// "bodies.0.velocity" → "bodies[0].velocity" (the reader's spelling of key paths).
std::string reader_path(const std::string& override_path) {
  std::string out;
  std::stringstream ss(override_path);
  for (std::string key; std::getline(ss, key, '.');) {
    if (!key.empty() && std::all_of(key.begin(), key.end(), ::isdigit))
      out += "[" + key + "]";
    else
      out += (out.empty() ? "" : ".") + key;
  }
  return out;
}

void apply_override(YAML::Node& root, const std::string& assignment, const std::string& file) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + assignment + ": expected key.path=value (e.g. --set time.end=0.2)");
  const std::string path = assignment.substr(0, eq);
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw InputError("--set " + assignment + ": the value is not valid YAML: " + e.msg);
  }
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string key; std::getline(ss, key, '.');) keys.push_back(key);
  std::function<void(YAML::Node, std::size_t)> set = [&](YAML::Node node, std::size_t i) {
    const std::string& key = keys[i];
    const bool index = !key.empty() && std::all_of(key.begin(), key.end(), ::isdigit);
    if (index && !node.IsSequence())
      throw InputError("--set " + assignment + ": '" + key + "' indexes a list, but " + file +
                       " has no list there");
    if (!index && node.IsDefined() && !node.IsNull() && !node.IsMap())
      throw InputError("--set " + assignment + ": '" + (i > 0 ? keys[i - 1] : file) +
                       "' is not a mapping, so it has no key '" + key + "'");
    if (index && key.size() > 9)
      throw InputError("--set " + assignment + ": index " + key + " is past the end of the list");
    if (i + 1 == keys.size()) {
      if (index) {
        if (std::stoul(key) >= node.size())
          throw InputError("--set " + assignment + ": index " + key +
                           " is past the end of the list");
        node[std::stoul(key)] = value;
      } else {
        node[key] = value;
      }
      return;
    }
    if (index) {
      if (std::stoul(key) >= node.size())
        throw InputError("--set " + assignment + ": index " + key + " is past the end of the list");
      set(node[std::stoul(key)], i + 1);
    } else {
      if (!node[key]) node[key] = YAML::Node(YAML::NodeType::Map);
      set(node[key], i + 1);
    }
  };
  set(root, 0);
}

FractureSpec read_fracture(const Reader& r, const YAML::Node& node, const std::string& path) {
  r.check_keys(
      node, path,
      {"tensile_strength", "cohesion", "friction_angle", "energy_I", "energy_II", "softening"},
      {"tensile_strength", "cohesion", "friction_angle", "energy_I", "energy_II"});
  FractureSpec f;
  f.tensile_strength =
      r.positive(node["tensile_strength"], path + ".tensile_strength", "tensile strength");
  f.cohesion = r.non_negative(node["cohesion"], path + ".cohesion", "cohesion");
  f.friction_angle_deg = r.number(node["friction_angle"], path + ".friction_angle");
  if (f.friction_angle_deg < 0.0 || f.friction_angle_deg >= 90.0)
    r.fail(node["friction_angle"], path + ".friction_angle",
           Reader::format(f.friction_angle_deg) +
               " is impossible: the friction angle is in degrees, 0 <= angle < 90");
  f.energy_I = r.positive(node["energy_I"], path + ".energy_I", "mode I fracture energy (J/m^2)");
  f.energy_II =
      r.positive(node["energy_II"], path + ".energy_II", "mode II fracture energy (J/m^2)");
  if (const YAML::Node s = node["softening"]) {
    const std::string sp = path + ".softening";
    r.check_keys(s, sp, {"a", "b", "c"});
    if (s["a"]) f.softening_a = r.positive(s["a"], sp + ".a", "softening parameter a");
    if (s["b"]) f.softening_b = r.positive(s["b"], sp + ".b", "softening parameter b");
    if (s["c"]) f.softening_c = r.positive(s["c"], sp + ".c", "softening parameter c");
  }
  return f;
}

MaterialSpec read_material(const Reader& r, const std::string& name, const YAML::Node& node,
                           const std::string& path) {
  r.check_keys(node, path, {"density", "elastic", "damping", "contact", "fracture"},
               {"density", "elastic"});
  MaterialSpec m;
  m.name = name;
  m.density = r.positive(node["density"], path + ".density", "density (kg/m^3)");
  const std::string ep = path + ".elastic";
  const YAML::Node e = node["elastic"];
  r.check_keys(e, ep, {"model", "young", "poisson"}, {"young", "poisson"});
  if (e["model"]) {
    const std::string model =
        r.choice(e["model"], ep + ".model", {"neo-hookean", "st-venant-kirchhoff"});
    m.elastic.model =
        model == "neo-hookean" ? ElasticModel::neo_hookean : ElasticModel::st_venant_kirchhoff;
  }
  m.elastic.young = r.positive(e["young"], ep + ".young", "Young's modulus (Pa)");
  m.elastic.poisson = r.number(e["poisson"], ep + ".poisson");
  if (!(m.elastic.poisson > -1.0 && m.elastic.poisson < 0.5))
    r.fail(e["poisson"], ep + ".poisson",
           Reader::format(m.elastic.poisson) +
               " is impossible: Poisson's ratio must satisfy -1 < poisson < 0.5");
  if (node["damping"]) {
    m.damping = r.non_negative(node["damping"], path + ".damping", "damping ratio");
    if (m.damping >= 1.0)
      r.fail(node["damping"], path + ".damping",
             Reader::format(m.damping) +
                 " is too large: the damping ratio (fraction of critical) must be < 1");
  }
  if (const YAML::Node c = node["contact"]) {
    const std::string cp = path + ".contact";
    r.check_keys(c, cp, {"penalty", "friction", "damping"});
    if (c["penalty"] && !r.is_auto(c["penalty"])) {
      m.contact.auto_penalty = false;
      m.contact.penalty =
          r.positive(c["penalty"], cp + ".penalty", "contact penalty (Pa) or 'auto'");
    }
    if (c["friction"])
      m.contact.friction = r.non_negative(c["friction"], cp + ".friction", "friction coefficient");
    if (c["damping"]) {
      m.contact.damping = r.non_negative(c["damping"], cp + ".damping", "contact damping ratio");
      if (m.contact.damping > 1.0)
        r.fail(c["damping"], cp + ".damping",
               Reader::format(m.contact.damping) +
                   " is too large: the contact damping ratio must be <= 1 (critical)");
    }
  }
  if (node["fracture"]) m.fracture = read_fracture(r, node["fracture"], path + ".fracture");
  return m;
}

MeshSpec read_mesh(const Reader& r, const YAML::Node& node, const std::string& path,
                   const std::string& scene_dir) {
  r.check_keys(node, path, {"box", "file", "physical"});
  MeshSpec mesh;
  if (node["box"] && node["file"]) r.fail(node, path, "give either 'box' or 'file', not both");
  if (const YAML::Node b = node["box"]) {
    const std::string bp = path + ".box";
    r.check_keys(b, bp, {"min", "max", "cells"}, {"min", "max"});
    mesh.kind = MeshSpec::Kind::box;
    mesh.box.min = r.vec3(b["min"], bp + ".min");
    mesh.box.max = r.vec3(b["max"], bp + ".max");
    for (int k = 0; k < 3; ++k)
      if (!(mesh.box.max[k] > mesh.box.min[k]))
        r.fail(b["max"], bp + ".max", "each component of max must be larger than min's");
    if (const YAML::Node cells = b["cells"]) {
      if (!cells.IsSequence() || cells.size() != 3)
        r.fail(cells, bp + ".cells", "expected three integers [nx, ny, nz]");
      for (int k = 0; k < 3; ++k) {
        mesh.box.cells[k] = r.integer(cells[k], bp + ".cells");
        if (mesh.box.cells[k] < 1) r.fail(cells[k], bp + ".cells", "each cell count must be >= 1");
      }
    }
    if (node["physical"])
      r.fail(node["physical"], path + ".physical", "'physical' applies to 'file' meshes only");
  } else if (const YAML::Node f = node["file"]) {
    mesh.kind = MeshSpec::Kind::file;
    const std::filesystem::path p(r.string(f, path + ".file"));
    mesh.file = p.is_absolute()
                    ? p.string()
                    : (std::filesystem::path(scene_dir) / p).lexically_normal().string();
    if (!std::filesystem::exists(mesh.file))
      r.fail(f, path + ".file",
             "mesh file '" + mesh.file + "' does not exist (paths are relative to the scene file)");
    if (node["physical"]) mesh.physical = r.string(node["physical"], path + ".physical");
  } else {
    r.fail(node, path, "a mesh needs one of: box, file");
  }
  return mesh;
}

std::vector<int> read_body_list(const Reader& r, const YAML::Node& node, const std::string& path,
                                const std::vector<std::string>& names) {
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

}  // namespace

Scene parse_scene(const std::string& yaml_text, const std::string& path,
                  const std::vector<std::string>& overrides) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  std::vector<std::pair<std::string, std::string>> overridden;
  for (const auto& o : overrides) {
    apply_override(root, o, path);
    overridden.emplace_back(reader_path(o.substr(0, o.find('='))), o);
  }
  const Reader r(path, overridden);
  const std::string scene_dir = std::filesystem::path(path).parent_path().string();

  Scene scene;
  scene.source_path = path;
  r.check_keys(root, "",
               {"name", "time", "gravity", "materials", "bodies", "interfaces", "loads", "output",
                "contact"},
               {"time", "materials", "bodies"});
  scene.name =
      root["name"] ? r.string(root["name"], "name") : std::filesystem::path(path).stem().string();

  const YAML::Node time = root["time"];
  r.check_keys(time, "time", {"end", "step", "safety"}, {"end"});
  scene.time.end = r.positive(time["end"], "time.end", "end time (s)");
  if (time["step"] && !r.is_auto(time["step"])) {
    scene.time.auto_step = false;
    scene.time.step = r.positive(time["step"], "time.step", "time step (s) or 'auto'");
  }
  if (time["safety"]) {
    scene.time.safety = r.positive(time["safety"], "time.safety", "safety factor");
    if (scene.time.safety > 1.0)
      r.fail(time["safety"], "time.safety",
             "must be in (0, 1]: the step is safety x the critical step");
  }
  if (root["gravity"]) scene.gravity = r.vec3(root["gravity"], "gravity");

  const YAML::Node materials = root["materials"];
  if (!materials.IsMap() || materials.size() == 0)
    r.fail(materials, "materials", "expected a mapping of material names to their properties");
  std::vector<std::string> material_names;
  for (auto it = materials.begin(); it != materials.end(); ++it) {
    const std::string name = r.key_name(it->first, "materials");
    if (std::find(material_names.begin(), material_names.end(), name) != material_names.end())
      r.fail(it->first, "materials." + name, "material '" + name + "' is defined twice");
    scene.materials.push_back(read_material(r, name, it->second, "materials." + name));
    material_names.push_back(name);
  }

  const YAML::Node bodies = root["bodies"];
  if (!bodies.IsSequence() || bodies.size() == 0)
    r.fail(bodies, "bodies", "expected a list of bodies (- name: ..., mesh: ..., material: ...)");
  std::vector<std::string> body_names;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const YAML::Node b = bodies[i];
    const std::string bp = "bodies[" + std::to_string(i) + "]";
    r.check_keys(b, bp,
                 {"name", "mesh", "material", "fixed", "joints", "velocity", "angular_velocity"},
                 {"mesh", "material"});
    BodySpec body;
    body.name = b["name"] ? r.string(b["name"], bp + ".name") : "body" + std::to_string(i);
    if (std::find(body_names.begin(), body_names.end(), body.name) != body_names.end())
      r.fail(b["name"] ? b["name"] : b, bp + ".name",
             "body name '" + body.name + "' is used twice; names must be unique");
    body.mesh = read_mesh(r, b["mesh"], bp + ".mesh", scene_dir);
    const std::string mat = r.string(b["material"], bp + ".material");
    const auto it = std::find(material_names.begin(), material_names.end(), mat);
    if (it == material_names.end()) {
      const std::string near = nearest_name(mat, material_names);
      r.fail(b["material"], bp + ".material",
             "no material named '" + mat + "'." +
                 (near.empty() ? "" : " Did you mean '" + near + "'?") +
                 " Materials: " + join(material_names) + ".");
    }
    body.material = static_cast<int>(it - material_names.begin());
    if (b["fixed"]) body.fixed = r.boolean(b["fixed"], bp + ".fixed");
    if (b["joints"])
      body.joints = r.choice(b["joints"], bp + ".joints", {"none", "all"}) == "all"
                        ? JointPlacement::all
                        : JointPlacement::none;
    if (body.joints == JointPlacement::all && !scene.materials[body.material].fracture)
      r.fail(b["joints"], bp + ".joints",
             "'all' needs fracture properties: add a 'fracture:' block to material '" + mat + "'");
    if (b["velocity"]) body.velocity = r.vec3(b["velocity"], bp + ".velocity");
    if (b["angular_velocity"])
      body.angular_velocity = r.vec3(b["angular_velocity"], bp + ".angular_velocity");
    body_names.push_back(body.name);
    scene.bodies.push_back(body);
  }

  if (const YAML::Node interfaces = root["interfaces"]) {
    if (!interfaces.IsSequence())
      r.fail(interfaces, "interfaces", "expected a list of {between: [a, b], fracture: {...}}");
    for (std::size_t i = 0; i < interfaces.size(); ++i) {
      const std::string ip = "interfaces[" + std::to_string(i) + "]";
      r.check_keys(interfaces[i], ip, {"between", "fracture"}, {"between", "fracture"});
      const auto pair = read_body_list(r, interfaces[i]["between"], ip + ".between", body_names);
      if (pair.size() != 2)
        r.fail(interfaces[i]["between"], ip + ".between", "expected exactly two body names");
      if (pair[0] == pair[1])
        r.fail(interfaces[i]["between"], ip + ".between",
               "an interface joins two different bodies; both are '" + body_names[pair[0]] + "'");
      InterfaceSpec spec;
      spec.body_a = pair[0];
      spec.body_b = pair[1];
      spec.fracture = read_fracture(r, interfaces[i]["fracture"], ip + ".fracture");
      scene.interfaces.push_back(spec);
    }
  }

  if (const YAML::Node loads = root["loads"]) {
    if (!loads.IsSequence()) r.fail(loads, "loads", "expected a list of loads");
    for (std::size_t i = 0; i < loads.size(); ++i) {
      const std::string lp = "loads[" + std::to_string(i) + "]";
      const YAML::Node l = loads[i];
      r.check_keys(l, lp, {"bodies", "region", "velocity"}, {"velocity"});
      LoadSpec load;
      if (l["bodies"] && l["region"]) r.fail(l, lp, "give either 'bodies' or 'region', not both");
      if (l["bodies"]) {
        load.bodies = read_body_list(r, l["bodies"], lp + ".bodies", body_names);
      } else if (const YAML::Node region = l["region"]) {
        r.check_keys(region, lp + ".region", {"box"}, {"box"});
        r.check_keys(region["box"], lp + ".region.box", {"min", "max"}, {"min", "max"});
        RegionSpec reg;
        reg.min = r.vec3(region["box"]["min"], lp + ".region.box.min");
        reg.max = r.vec3(region["box"]["max"], lp + ".region.box.max");
        for (int k = 0; k < 3; ++k)
          if (reg.max[k] < reg.min[k])
            r.fail(region["box"]["max"], lp + ".region.box.max",
                   "each component of max must be at least min's (the box would hold no node)");
        load.region = reg;
      } else {
        r.fail(l, lp, "a load needs 'bodies' or 'region' to say where it acts");
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

  if (const YAML::Node out = root["output"]) {
    r.check_keys(out, "output", {"every", "fields", "checkpoint_every", "energy_every"});
    if (out["every"])
      scene.output.every = r.non_negative(out["every"], "output.every", "frame interval (s)");
    if (out["checkpoint_every"])
      scene.output.checkpoint_every = r.non_negative(
          out["checkpoint_every"], "output.checkpoint_every", "checkpoint interval (s)");
    if (out["energy_every"])
      scene.output.energy_every =
          r.non_negative(out["energy_every"], "output.energy_every", "energy row interval (s)");
    if (const YAML::Node fields = out["fields"]) {
      if (!fields.IsSequence()) r.fail(fields, "output.fields", "expected a list of field names");
      scene.output.fields.clear();
      for (std::size_t i = 0; i < fields.size(); ++i)
        scene.output.fields.push_back(
            r.choice(fields[i], "output.fields",
                     {"displacement", "velocity", "stress", "damage", "contact_force"}));
    }
  }

  if (const YAML::Node contact = root["contact"]) {
    r.check_keys(contact, "contact", {"buffer"});
    if (contact["buffer"] && !r.is_auto(contact["buffer"]))
      scene.contact_buffer =
          r.positive(contact["buffer"], "contact.buffer", "contact detection buffer (m) or 'auto'");
  }
  return scene;
}

Scene read_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in)
    throw InputError(path + ": cannot open the scene file (does it exist and is it readable?)");
  std::stringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path, overrides);
}

}  // namespace fdem
