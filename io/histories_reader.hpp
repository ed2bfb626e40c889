// Readers of the scene's load names and of output.histories (docs/scene-format.md, "Histories"),
// split from io/scene_reader.cpp.  Internal to io/.
#pragma once

#include <string>
#include <vector>

#include "core/scene.hpp"
#include "io/yaml_reader.hpp"

namespace fdem {

// The `name` of load `l` at key path `path` (default load<index>), unique among `earlier`.
std::string read_load_name(const scene_yaml::Reader& r, const YAML::Node& l,
                           const std::string& path, const std::vector<LoadSpec>& earlier);

// output.histories, after the scene's time, bodies and loads have been read.
HistoriesSpec read_histories(const scene_yaml::Reader& r, const YAML::Node& node,
                             const std::string& path, const Scene& scene,
                             const std::vector<std::string>& body_names);

}  // namespace fdem
