#include "io/scene_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include "core/checked_cast.hpp"
#include "core/error.hpp"
#include "io/histories_reader.hpp"
#include "io/load_reader.hpp"
#include "io/scene_reader_support.hpp"
#include "io/yaml_reader.hpp"

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

using scene_yaml::join;
using scene_yaml::Reader;

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

// {type: none} | {type: weibull, modulus: m, seed: s} | {type: normal, cov: v, seed: s}
StrengthDistributionSpec read_strength_distribution(const Reader& r, const YAML::Node& node,
                                                    const std::string& path) {
  using Type = StrengthDistributionSpec::Type;
  if (!node.IsMap())
    r.fail(node, path,
           "expected {type: weibull, modulus: m, seed: s}, {type: normal, cov: v, seed: s} or "
           "{type: none}");
  StrengthDistributionSpec d;
  const std::string type = r.choice(node["type"], path + ".type", {"none", "weibull", "normal"});
  if (type == "none") {
    r.check_keys(node, path, {"type", "seed"}, {"type"});
    return d;
  }
  if (type == "weibull") {
    r.check_keys(node, path, {"type", "modulus", "seed"}, {"type", "modulus", "seed"});
    d.type = Type::weibull;
    d.modulus = r.number(node["modulus"], path + ".modulus");
    if (d.modulus < 1.0)  // below 1 the spread exceeds an exponential distribution's (cov > 1)
      r.fail(node["modulus"], path + ".modulus",
             Reader::format(d.modulus) +
                 " is impossible: the Weibull modulus must be >= 1 (1: cov 1; 2.1: cov 0.5; 5: "
                 "cov 0.23; 10: cov 0.12)");
  } else {
    r.check_keys(node, path, {"type", "cov", "seed"}, {"type", "cov", "seed"});
    d.type = Type::normal;
    d.cov = r.positive(node["cov"], path + ".cov", "the coefficient of variation");
    // Factors are drawn from the normal distribution cut at 0 (a strength is positive); up to
    // cov = 0.3 the cut removes under 0.05 % of the draws (z < −3.33), moving the mean by
    // < 0.1 % and the spread by < 0.5 %.
    if (d.cov > 0.3)
      r.fail(node["cov"], path + ".cov",
             Reader::format(d.cov) +
                 " is too large: cov must be in (0, 0.3] (a wider normal spread puts strengths "
                 "below zero; use type: weibull for a wide, skewed spread — modulus 2.1 gives "
                 "cov 0.5)");
  }
  const std::int64_t seed = r.integer64(node["seed"], path + ".seed");
  if (seed < 0 || seed >= (std::int64_t{1} << 53))
    r.fail(node["seed"], path + ".seed",
           std::to_string(seed) + " is impossible: the seed is an integer >= 0 and < 2^53");
  d.seed = static_cast<std::uint64_t>(seed);
  return d;
}

FractureSpec read_fracture(const Reader& r, const YAML::Node& node, const std::string& path) {
  r.check_keys(node, path,
               {"tensile_strength", "cohesion", "friction_angle", "energy_I", "energy_II",
                "softening", "penalty", "strength_distribution"},
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
  if (const YAML::Node p = node["penalty"]) {  // auto | Pa | {normal: .., tangential: ..}
    const std::string pp = path + ".penalty";
    const auto value = [&](const YAML::Node& v, const std::string& vp) {
      return r.is_auto(v) ? 0.0 : r.positive(v, vp, "the joint penalty (Pa, or 'auto' = 50 E)");
    };
    if (p.IsMap()) {
      r.check_keys(p, pp, {"normal", "tangential"});
      if (p["normal"]) f.normal_penalty = value(p["normal"], pp + ".normal");
      if (p["tangential"]) f.tangential_penalty = value(p["tangential"], pp + ".tangential");
    } else {
      f.normal_penalty = f.tangential_penalty = value(p, pp);
    }
  }
  if (const YAML::Node d = node["strength_distribution"])
    f.strength_distribution = read_strength_distribution(r, d, path + ".strength_distribution");
  f.key = path;
  f.location = r.location(node);
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

void read_limits(const Reader& r, const YAML::Node& node, LimitsSpec& limits) {
  r.check_keys(node, "limits", {"max_steps", "max_memory_per_rank"});
  if (node["max_steps"])
    limits.max_steps = r.positive(node["max_steps"], "limits.max_steps",
                                  "the largest number of time steps of a run");
  if (node["max_memory_per_rank"] && !r.is_auto(node["max_memory_per_rank"]))
    limits.max_memory_per_rank =
        r.positive(node["max_memory_per_rank"], "limits.max_memory_per_rank",
                   "the memory one rank may use (bytes) or 'auto'");
}

// An interval must move time forward: t + every must differ from t up to time.end (and a frame
// every 1e-12 of the run is already more than any step count allows), else the loop that
// advances the next output time never ends.
void check_intervals(const Reader& r, const YAML::Node& output, const Scene& scene) {
  const double shortest = 1e-12 * scene.time.end;  // s
  const std::pair<const char*, double> intervals[] = {
      {"every", scene.output.every},
      {"energy_every", scene.output.energy_every},
      {"checkpoint_every", scene.output.checkpoint_every}};
  for (const auto& [key, every] : intervals)
    if (every > 0.0 && every < shortest)
      r.fail(output[key], std::string("output.") + key,
             Reader::format(every) + " s cannot advance time: it is below 1e-12 x time.end (" +
                 Reader::format(scene.time.end) + " s). Use 0 (first and last only) or at least " +
                 Reader::format(shortest) + " s.");
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
                "contact", "parallel", "limits", "absorbing", "initial_stress", "quasi_static"},
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
    body.mesh = scene_reading::read_mesh(r, b["mesh"], bp + ".mesh", scene_dir);
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
    if (b["joints"]) {
      const std::string joints =
          r.choice(b["joints"], bp + ".joints", {"none", "all", "interfaces"});
      body.joints = joints == "all"          ? JointPlacement::all
                    : joints == "interfaces" ? JointPlacement::interfaces
                                             : JointPlacement::none;
      if (body.joints != JointPlacement::none && !scene.materials[body.material].fracture)
        r.fail(b["joints"], bp + ".joints",
               "'" + joints + "' needs fracture properties: add a 'fracture:' block to material '" +
                   mat + "'");
    }
    if (b["velocity"]) body.velocity = r.vec3(b["velocity"], bp + ".velocity");
    if (b["angular_velocity"])
      body.angular_velocity = r.vec3(b["angular_velocity"], bp + ".angular_velocity");
    for (const char* key : {"velocity", "angular_velocity"})  // it would be dropped silently
      if (body.fixed && b[key])
        r.fail(b[key], bp + "." + key,
               "a fixed body does not move: remove it, or move the body with a base_motion or a "
               "velocity load");
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

  if (const YAML::Node loads = root["loads"]) read_loads(r, loads, scene_dir, body_names, scene);

  if (const YAML::Node absorbing = root["absorbing"])
    scene.absorbing = scene_reading::read_absorbing(r, absorbing, body_names);
  if (const YAML::Node stress = root["initial_stress"])
    scene.initial_stress = scene_reading::read_initial_stress(r, stress, body_names, scene.gravity);

  if (const YAML::Node out = root["output"]) {
    r.check_keys(out, "output",
                 {"every", "fields", "checkpoint_every", "energy_every", "format", "mpi_io_hints",
                  "histories"});
    if (out["histories"])
      scene.output.histories =
          read_histories(r, out["histories"], "output.histories", scene, body_names);
    if (out["format"])
      scene.output.format = r.choice(out["format"], "output.format", {"vtu", "xdmf"}) == "xdmf"
                                ? OutputSpec::FrameFormat::xdmf
                                : OutputSpec::FrameFormat::vtu;
    if (const YAML::Node hints = out["mpi_io_hints"]) {
      // Passed to MPI_Info_set as given: MPI-IO ignores keys it does not know, so only the form
      // is checked here (a key is a plain name, a value one scalar).
      if (!hints.IsMap())
        r.fail(hints, "output.mpi_io_hints",
               "expected a mapping of MPI-IO hint names to values, e.g. {striping_factor: 16, "
               "romio_cb_write: enable}");
      for (auto it = hints.begin(); it != hints.end(); ++it) {
        const std::string key = r.key_name(it->first, "output.mpi_io_hints");
        const std::string hint_path = "output.mpi_io_hints." + key;
        if (key.empty() || !std::all_of(key.begin(), key.end(), [](char c) {
              return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
            }))
          r.fail(it->first, hint_path, "an MPI-IO hint name is letters, digits and '_'");
        if (!it->second.IsScalar() || it->second.Scalar().empty())
          r.fail(it->second, hint_path,
                 "expected one value (a number or a word), e.g. 16 or enable");
        scene.output.mpi_io_hints.emplace_back(key, it->second.Scalar());
      }
    }
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

  if (const YAML::Node parallel = root["parallel"]) {
    r.check_keys(parallel, "parallel",
                 {"rebalance_threshold", "redistribute_every", "distributed_start", "partitioner",
                  "gid_offset", "migration", "repartition"});
    if (parallel["migration"])
      scene.parallel.migration =
          r.choice(parallel["migration"], "parallel.migration", {"incremental", "full"});
    if (parallel["repartition"])
      scene.parallel.repartition =
          r.choice(parallel["repartition"], "parallel.repartition", {"measured", "threshold"});
    if (parallel["partitioner"])
      scene.parallel.partitioner = r.choice(parallel["partitioner"], "parallel.partitioner",
                                            {"rib", "rcb", "hsfc", "random"});
    if (parallel["distributed_start"])
      scene.parallel.distributed_start =
          r.boolean(parallel["distributed_start"], "parallel.distributed_start");
    if (parallel["rebalance_threshold"])
      scene.parallel.rebalance_threshold =
          r.non_negative(parallel["rebalance_threshold"], "parallel.rebalance_threshold",
                         "load imbalance (max/mean cost) above which ranks re-partition");
    if (parallel["redistribute_every"]) {
      const int every = r.integer(parallel["redistribute_every"], "parallel.redistribute_every");
      if (every < 0)
        r.fail(parallel["redistribute_every"], "parallel.redistribute_every",
               "expected a number of steps >= 0 (0: only at contact detections)");
      scene.parallel.redistribute_every = every;
    }
    if (parallel["gid_offset"]) {
      // gid_offset + N must fit 63 bits, with room for the start-up's 4 × tet index.
      const std::int64_t offset = r.integer64(parallel["gid_offset"], "parallel.gid_offset");
      if (offset < 0 || offset >= (std::int64_t{1} << 62))
        r.fail(parallel["gid_offset"], "parallel.gid_offset",
               std::to_string(offset) +
                   " is impossible: the gid offset (a testing aid) must be >= 0 and < 2^62 = " +
                   std::to_string(std::int64_t{1} << 62));
      scene.parallel.gid_offset = offset;
    }
  }

  if (const YAML::Node quasi = root["quasi_static"])
    scene.quasi_static = scene_reading::read_quasi_static(r, quasi);
  if (const YAML::Node limits = root["limits"]) read_limits(r, limits, scene.limits);
  check_intervals(r, root["output"], scene);

  if (const YAML::Node contact = root["contact"]) {
    r.check_keys(contact, "contact",
                 {"buffer", "skip_enclosed", "narrowing", "friction_anchor_lag", "dashpot",
                  "sliver_tolerance", "clip_replay", "formulation"});
    if (contact["sliver_tolerance"]) {
      const double tolerance = r.number(contact["sliver_tolerance"], "contact.sliver_tolerance");
      if (!(tolerance >= 0.0 && tolerance <= 1e-6))
        r.fail(contact["sliver_tolerance"], "contact.sliver_tolerance",
               Reader::format(tolerance) +
                   " is impossible: the largest nodal force a skipped pair may carry, as a "
                   "fraction of p·ℓ², must be between 0 (integrate every pair) and 1e-6 "
                   "(the default)");
      scene.contact_sliver_tolerance = tolerance;
    }
    if (contact["dashpot"])
      scene.contact_body_dashpot =
          r.choice(contact["dashpot"], "contact.dashpot", {"bodies", "tets"}) == "bodies";
    if (contact["friction_anchor_lag"])
      scene.contact_friction_anchor_lag =
          r.positive(contact["friction_anchor_lag"], "contact.friction_anchor_lag",
                     "time (s) with which stick springs' anchors follow the contact");
    if (contact["formulation"]) {
      const std::string formulation =
          r.choice(contact["formulation"], "contact.formulation", {"auto", "potential", "corners"});
      scene.contact_formulation = formulation == "corners"     ? ContactFormulation::corners
                                  : formulation == "potential" ? ContactFormulation::potential
                                                               : ContactFormulation::automatic;
    }
    if (contact["clip_replay"])
      scene.contact_clip_replay = r.boolean(contact["clip_replay"], "contact.clip_replay");
    if (contact["skip_enclosed"])
      scene.contact_skip_enclosed = r.boolean(contact["skip_enclosed"], "contact.skip_enclosed");
    if (contact["narrowing"])
      scene.contact_exact_narrowing =
          r.choice(contact["narrowing"], "contact.narrowing", {"exact", "face_planes"}) == "exact";
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
