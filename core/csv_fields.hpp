// Fields of the small CSV files users supply (acceleration records, amplitude tables): trimmed
// text and whole-field finite numbers, so that every reader rejects the same malformed rows.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

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

// Rows "time, value" of a CSV file: blank lines, lines starting with '#' and one header line
// before the first row are skipped.  InputError naming the file and line for any other line that
// is not two numbers, for times that are negative or do not increase, and for fewer than two rows.
// `value_name` names the column in messages ("acceleration"), `what` the file ("an acceleration
// record").
struct TimeValueRows {
  std::vector<double> time, value;
};
TimeValueRows read_time_value_rows(const std::string& path, const std::string& value_name,
                                   const std::string& what);

}  // namespace fdem::csv_fields
