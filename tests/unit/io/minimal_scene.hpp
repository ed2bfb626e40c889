// A minimal valid scene as text, and the message a scene text's InputError carries: what the
// scene reader's tests edit and check.
#pragma once

#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

namespace fdem::test_scenes {

// The message of the InputError that parsing `text` (as "scene.yaml") raises; "" when it parses.
inline std::string input_error(const std::string& text,
                               const std::vector<std::string>& overrides = {}) {
  try {
    fdem::parse_scene(text, "scene.yaml", overrides);
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

// A valid scene; line numbers (1-based) are quoted by the tests that edit one line.
//  1 time: {end: 0.1}
//  2 materials:
//  3   rock:
//  4     density: 2500
//  5     elastic: {young: 1.0e9, poisson: 0.25}
//  6 bodies:
//  7   - name: block
//  8     mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}
//  9     material: rock
inline std::vector<std::string> minimal_lines() {
  return {"time: {end: 0.1}",
          "materials:",
          "  rock:",
          "    density: 2500",
          "    elastic: {young: 1.0e9, poisson: 0.25}",
          "bodies:",
          "  - name: block",
          "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}}",
          "    material: rock"};
}

inline std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

// The minimal scene with line `line` (1-based) replaced.
inline std::string minimal_with(int line, const std::string& replacement) {
  auto lines = minimal_lines();
  lines.at(line - 1) = replacement;
  return join_lines(lines);
}

inline std::string minimal_plus(const std::string& extra) {
  return join_lines(minimal_lines()) + extra;
}

}  // namespace fdem::test_scenes
