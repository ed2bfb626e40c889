// Reads and validates a scene file (YAML, see docs/scene-format.md).  Every problem is reported as
// fdem::InputError "FILE:LINE:COLUMN: key.path: what is wrong; what is valid".
#pragma once

#include <string>
#include <vector>

#include "core/scene.hpp"

namespace fdem {

// overrides: "key.path=value" strings from --set, applied before validation (value is YAML).
Scene read_scene(const std::string& path, const std::vector<std::string>& overrides = {});
Scene parse_scene(const std::string& yaml_text, const std::string& path_for_messages,
                  const std::vector<std::string>& overrides = {});

// Closest candidate by edit distance, or "" if none is reasonably close.
std::string nearest_name(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace fdem
