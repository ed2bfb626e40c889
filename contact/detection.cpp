#include "contact/detection.hpp"

#include <cmath>
#include <limits>

namespace fdem {

double max_node_displacement(const double* x, const double* x_at_detection, LocalIndex n_nodes) {
  double max_squared = 0.0;
  for (LocalIndex i = 0; i < n_nodes; ++i) {
    const double dx = x[3 * i] - x_at_detection[3 * i];
    const double dy = x[3 * i + 1] - x_at_detection[3 * i + 1];
    const double dz = x[3 * i + 2] - x_at_detection[3 * i + 2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 <= max_squared)) {  // also true for NaN
      if (std::isnan(d2)) return std::numeric_limits<double>::infinity();
      max_squared = d2;
    }
  }
  return std::sqrt(max_squared);
}

}  // namespace fdem
