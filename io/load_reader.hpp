// Readers of the scene's `loads:` list and of time histories (docs/scene-format.md, "Loads",
// "Time histories"), split from io/scene_reader.cpp.  Internal to io/.
#pragma once

#include <string>
#include <vector>

#include "core/scene.hpp"
#include "io/yaml_reader.hpp"

namespace fdem {

// A list of body names → their indices; an unknown name names the nearest one and the bodies.
std::vector<int> read_body_list(const scene_yaml::Reader& r, const YAML::Node& node,
                                const std::string& path, const std::vector<std::string>& names);

// {box: {min: [x, y, z], max: [x, y, z]}}: the region of a load or an absorbing boundary.
RegionSpec read_box_region(const scene_yaml::Reader& r, const YAML::Node& region,
                           const std::string& path);

// loads: appends each load to scene.loads (after the bodies have been read).
void read_loads(const scene_yaml::Reader& r, const YAML::Node& loads, const std::string& scene_dir,
                const std::vector<std::string>& body_names, Scene& scene);

// A time history at key `path`: a number (constant), {table: [[t, v], ...]}, {file: amp.csv}
// (rows "time, value"; path relative to the scene) or {smooth_step: {start, end, from, to,
// shape}}.
TimeHistory read_time_history(const scene_yaml::Reader& r, const YAML::Node& node,
                              const std::string& path, const std::string& scene_dir);

// Reads a CSV table of rows "time, value" (s, any unit): blank lines, lines starting with '#' and
// one header line before the first row are skipped.  InputError naming the file and line for
// any other line that is not two numbers, times that are negative or do not increase, or fewer
// than two rows.
TimeHistory read_history_file(const std::string& path);

}  // namespace fdem
