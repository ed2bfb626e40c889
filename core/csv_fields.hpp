// Fields of the small CSV files users supply (acceleration records, amplitude tables): trimmed
// text and whole-field finite numbers, so that every reader rejects the same malformed rows.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

namespace fdem::csv_fields {

inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// A whole field as a finite number (false for an empty field, trailing text, inf or nan).
inline bool parse_number(const std::string& field, double& out) {
  const std::string f = trim(field);
  if (f.empty()) return false;
  char* end = nullptr;
  out = std::strtod(f.c_str(), &end);
  return end == f.c_str() + f.size() && std::isfinite(out);
}

}  // namespace fdem::csv_fields
