// Scene keys of boundaries and initial state: `absorbing:` (viscous absorbing boundaries),
// `initial_stress:` (uniform or geostatic in-situ stress) and `quasi_static:` (local damping, for
// settling or quasi-static runs).  docs/scene-format.md.
#include <string>
#include <vector>

#include "io/load_reader.hpp"
#include "io/scene_reader_support.hpp"

namespace fdem::scene_reading {

std::vector<AbsorbingSpec> read_absorbing(const Reader& r, const YAML::Node& node,
                                          const std::vector<std::string>& body_names) {
  if (!node.IsSequence())
    r.fail(node, "absorbing",
           "expected a list of absorbing boundaries, e.g. [{region: {box: {min: [x, y, z], max: "
           "[x, y, z]}}}]");
  std::vector<AbsorbingSpec> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string path = "absorbing[" + std::to_string(i) + "]";
    const YAML::Node a = node[i];
    r.check_keys(a, path, {"region", "bodies"}, {"region"});
    AbsorbingSpec spec;
    spec.region = read_box_region(r, a["region"], path + ".region");
    if (a["bodies"]) spec.bodies = read_body_list(r, a["bodies"], path + ".bodies", body_names);
    out.push_back(spec);
  }
  return out;
}

std::vector<InitialStressSpec> read_initial_stress(const Reader& r, const YAML::Node& node,
                                                   const std::vector<std::string>& body_names,
                                                   const Vec3& gravity) {
  if (!node.IsSequence())
    r.fail(node, "initial_stress",
           "expected a list, e.g. [{uniform: [sxx, syy, szz, syz, sxz, sxy]}] (Pa, tension "
           "positive) or [{geostatic: {surface: z, k0: 0.5}}]");
  std::vector<InitialStressSpec> out;
  std::vector<bool> taken(body_names.size(), false);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string path = "initial_stress[" + std::to_string(i) + "]";
    const YAML::Node s = node[i];
    r.check_keys(s, path, {"uniform", "geostatic", "bodies"});
    InitialStressSpec spec;
    if (static_cast<bool>(s["uniform"]) == static_cast<bool>(s["geostatic"]))
      r.fail(s, path, "give one of 'uniform' or 'geostatic'");
    if (const YAML::Node u = s["uniform"]) {
      spec.kind = InitialStressSpec::Kind::uniform;
      if (!u.IsSequence() || u.size() != 6)
        r.fail(u, path + ".uniform",
               "expected 6 numbers [sxx, syy, szz, syz, sxz, sxy] (Pa, Cauchy, tension positive)");
      for (int k = 0; k < 6; ++k) spec.stress[k] = r.number(u[k], path + ".uniform");
    } else {
      const YAML::Node g = s["geostatic"];
      spec.kind = InitialStressSpec::Kind::geostatic;
      r.check_keys(g, path + ".geostatic", {"surface", "k0"}, {"surface", "k0"});
      spec.surface = r.number(g["surface"], path + ".geostatic.surface");
      spec.k0 =
          r.non_negative(g["k0"], path + ".geostatic.k0", "K0 (horizontal over vertical stress)");
      if (!(gravity.norm() > 0.0))
        r.fail(g, path + ".geostatic",
               "a geostatic stress is the weight of the ground above: it needs a non-zero "
               "top-level 'gravity' (e.g. gravity: [0, 0, -9.81])");
    }
    if (s["bodies"]) spec.bodies = read_body_list(r, s["bodies"], path + ".bodies", body_names);
    // Each body gets at most one initial stress: an overlap is more likely a mistake than meant.
    std::vector<int> bodies = spec.bodies;
    if (bodies.empty())
      for (std::size_t b = 0; b < body_names.size(); ++b) bodies.push_back(static_cast<int>(b));
    for (int b : bodies) {
      if (taken[static_cast<std::size_t>(b)])
        r.fail(s, path,
               "body '" + body_names[static_cast<std::size_t>(b)] +
                   "' already has an initial stress from an earlier entry: give each body at "
                   "most one (list 'bodies' to split them)");
      taken[static_cast<std::size_t>(b)] = true;
    }
    out.push_back(spec);
  }
  return out;
}

QuasiStaticSpec read_quasi_static(const Reader& r, const YAML::Node& node) {
  r.check_keys(node, "quasi_static", {"damping", "local_damping", "until", "equilibrium_ratio"},
               {});
  QuasiStaticSpec spec;
  if (node["damping"] &&
      r.choice(node["damping"], "quasi_static.damping", {"local", "kinetic"}) == "kinetic")
    spec.damping = QuasiStaticDamping::kinetic;
  // Kinetic damping may take local damping besides, for the vibrations of the highest modes.
  if (!spec.kinetic() && !node["local_damping"])
    r.fail(node, "quasi_static.local_damping",
           "missing required key 'local_damping' (0.8 is usual), or give damping: kinetic");
  if (node["local_damping"]) {
    const double alpha = spec.local_damping =
        r.number(node["local_damping"], "quasi_static.local_damping");
    if (!(alpha < 1.0 && (spec.kinetic() ? alpha >= 0.0 : alpha > 0.0)))
      r.fail(node["local_damping"], "quasi_static.local_damping",
             spec.kinetic() ? "must be in [0, 1): the fraction of a node's unbalanced force taken "
                              "by local damping besides the kinetic damping (0, none, by default)"
                            : "must be in (0, 1): the fraction of a node's unbalanced force taken "
                              "by the damping (0.8 is usual)");
  }
  if (node["until"])
    spec.until = r.positive(node["until"], "quasi_static.until",
                            "time (s) after which the run is dynamic again");
  if (node["equilibrium_ratio"]) {
    spec.equilibrium_ratio = r.number(node["equilibrium_ratio"], "quasi_static.equilibrium_ratio");
    if (!(spec.equilibrium_ratio > 0.0 && spec.equilibrium_ratio < 1.0))
      r.fail(node["equilibrium_ratio"], "quasi_static.equilibrium_ratio",
             "must be in (0, 1): the run ends at equilibrium, when the mean unbalanced force "
             "falls below this fraction of the weight and support forces (1e-4 to 1e-6 are usual)");
  }
  return spec;
}

}  // namespace fdem::scene_reading
