// What the scene reader's files share beyond the YAML Reader (io/yaml_reader.hpp): body lists,
// the mesh reader and the boundary readers (io/scene_reader*.cpp only).
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
#include "io/load_reader.hpp"
#include "io/scene_reader.hpp"
#include "io/yaml_reader.hpp"

namespace fdem {

namespace scene_reading {

using scene_yaml::join;
using scene_yaml::Reader;

using fdem::read_body_list;  // io/load_reader

// `absorbing:` (io/scene_reader_boundaries.cpp): a list of {region: {box: {min, max}}, bodies}.
std::vector<AbsorbingSpec> read_absorbing(const Reader& r, const YAML::Node& node,
                                          const std::vector<std::string>& body_names);
// `initial_stress:`: a list of {uniform: [6 values]} or {geostatic: {surface, k0}}, each with
// optional bodies; geostatic needs `gravity`.
std::vector<InitialStressSpec> read_initial_stress(const Reader& r, const YAML::Node& node,
                                                   const std::vector<std::string>& body_names,
                                                   const Vec3& gravity);

// A body's `mesh:` (io/scene_reader_meshes.cpp): box, file (relative to `scene_dir`), wall, arch
// or tower.
MeshSpec read_mesh(const Reader& r, const YAML::Node& node, const std::string& path,
                   const std::string& scene_dir);

// `quasi_static:` (io/scene_reader_boundaries.cpp): {local_damping: α, until: t}.
QuasiStaticSpec read_quasi_static(const Reader& r, const YAML::Node& node);

}  // namespace scene_reading
}  // namespace fdem
