// The YAML accessors of the scene reader (io/scene_reader.cpp and the readers of its parts):
// every value is read with its key path, so that a message names the file, line, column and key.
// Internal to io/.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "io/scene_reader.hpp"

namespace fdem::scene_yaml {

inline std::string join(const std::vector<std::string>& items) {
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

  // "FILE:LINE:COLUMN: key.path" (or "FILE: --set ASSIGNMENT: key.path" for an overridden
  // value): where a message about `at` points.
  std::string location(const YAML::Node& at, const std::string& path) const {
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
    msg << ": " << (path.empty() ? std::string("(top level)") : path);
    return msg.str();
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& path,
                         const std::string& what) const {
    throw InputError(location(at, path) + ": " + what);
  }

  // yaml-cpp hands back an invalid node for a key missing from a const mapping, and asking its
  // kind throws; every accessor asks this first so a missing key is an input error.
  void require_present(const YAML::Node& node, const std::string& path,
                       const std::string& expected) const {
    if (!node.IsDefined()) fail(node, path, "missing; expected " + expected);
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
    require_present(node, path, "a mapping (key: value pairs) with keys " + join(allowed));
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
    require_present(node, path, "a number");
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
    require_present(node, path, "an integer");
    if (!node.IsScalar()) fail(node, path, "expected an integer");
    try {
      return node.as<int>();
    } catch (const YAML::Exception&) {
      fail(node, path, "expected an integer, got '" + node.Scalar() + "'");
    }
  }

  std::int64_t integer64(const YAML::Node& node, const std::string& path) const {
    require_present(node, path, "an integer");
    if (!node.IsScalar()) fail(node, path, "expected an integer");
    try {
      return node.as<std::int64_t>();
    } catch (const YAML::Exception&) {
      fail(node, path, "expected an integer, got '" + node.Scalar() + "'");
    }
  }

  bool boolean(const YAML::Node& node, const std::string& path) const {
    require_present(node, path, "true or false");
    if (!node.IsScalar()) fail(node, path, "expected true or false");
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(node, path, "expected true or false, got '" + node.Scalar() + "'");
    }
  }

  std::string string(const YAML::Node& node, const std::string& path) const {
    require_present(node, path, "a text value");
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
    require_present(node, path, "three numbers [x, y, z]");
    if (!node.IsSequence() || node.size() != 3)
      fail(node, path, "expected three numbers [x, y, z]");
    return {number(node[0], path + "[0]"), number(node[1], path + "[1]"),
            number(node[2], path + "[2]")};
  }

  // "auto" or a number.
  bool is_auto(const YAML::Node& node) const {
    return node.IsDefined() && node.IsScalar() && node.Scalar() == "auto";
  }

  static std::string format(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  const std::string& file() const { return file_; }
  // "file:line" of a node, or the file when the node has no place in it (an override).
  std::string location(const YAML::Node& node) const {
    const YAML::Mark mark = node.IsDefined() ? node.Mark() : YAML::Mark::null_mark();
    return mark.line >= 0 ? file_ + ":" + std::to_string(mark.line + 1) : file_;
  }

 private:
  std::string file_;
  std::vector<std::pair<std::string, std::string>> overridden_;
};

}  // namespace fdem::scene_yaml
