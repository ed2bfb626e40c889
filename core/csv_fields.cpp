#include "core/csv_fields.hpp"

#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace fdem::csv_fields {

TimeValueRows read_time_value_rows(const std::string& path, const std::string& value_name,
                                   const std::string& what) {
  std::ifstream in(path);
  if (!in)
    throw InputError(path + ": cannot open " + what + " (CSV rows: time, " + value_name + ")");
  TimeValueRows rows;
  std::string line;
  int line_number = 0;
  bool header_allowed = true;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') continue;
    const auto comma = text.find(',');
    double t = 0, v = 0;
    const bool two = comma != std::string::npos && text.find(',', comma + 1) == std::string::npos;
    if (!two || !parse_number(text.substr(0, comma), t) ||
        !parse_number(text.substr(comma + 1), v)) {
      if (header_allowed && rows.time.empty()) {  // a column header such as "time,value"
        header_allowed = false;
        continue;
      }
      std::ostringstream msg;
      msg << path << ":" << line_number << ": expected a row 'time, " << value_name
          << "' (two numbers separated by a comma), got '" << text << "'";
      throw InputError(msg.str());
    }
    header_allowed = false;
    std::ostringstream where;
    where << path << ":" << line_number << ": time " << t << " s";
    if (t < 0.0) throw InputError(where.str() + " is negative; times start at t >= 0");
    if (!rows.time.empty() && !(t > rows.time.back())) {
      std::ostringstream previous;
      previous << rows.time.back();
      throw InputError(where.str() + " does not increase (previous row: " + previous.str() + " s)");
    }
    rows.time.push_back(t);
    rows.value.push_back(v);
  }
  if (rows.time.size() < 2)
    throw InputError(path + ": " + what + " needs at least two rows 'time, " + value_name +
                     "' (found " + std::to_string(rows.time.size()) + ")");
  return rows;
}

}  // namespace fdem::csv_fields
