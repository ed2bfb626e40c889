// What the scene reader's files share beyond the YAML Reader (io/yaml_reader.hpp): body lists and
// the boundary readers (io/scene_reader*.cpp only).
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/scene.hpp"
#include "core/types.hpp"
#include "io/scene_reader.hpp"
#include "io/yaml_reader.hpp"

namespace fdem {

namespace scene_reading {

using scene_yaml::join;
using scene_yaml::Reader;

inline std::vector<int> read_body_list(const Reader& r, const YAML::Node& node,
                                       const std::string& path,
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

// `absorbing:` (io/scene_reader_boundaries.cpp): a list of {region: {box: {min, max}}, bodies}.
std::vector<AbsorbingSpec> read_absorbing(const Reader& r, const YAML::Node& node,
                                          const std::vector<std::string>& body_names);
// `initial_stress:`: a list of {uniform: [6 values]} or {geostatic: {surface, k0}}, each with
// optional bodies; geostatic needs `gravity`.
std::vector<InitialStressSpec> read_initial_stress(const Reader& r, const YAML::Node& node,
                                                   const std::vector<std::string>& body_names,
                                                   const Vec3& gravity);

}  // namespace scene_reading
}  // namespace fdem
