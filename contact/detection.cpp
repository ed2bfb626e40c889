#include "contact/detection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdem {

namespace {

// Largest |x[node(k)] − x_at_detection[k]| over k < count; +infinity for NaN.
template <class NodeOf>
double largest_displacement(const double* x, const double* x_at_detection, std::size_t count,
                            NodeOf node_of) {
  double max_squared = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const double* p = x + 3 * static_cast<std::size_t>(node_of(k));
    const double dx = p[0] - x_at_detection[3 * k];
    const double dy = p[1] - x_at_detection[3 * k + 1];
    const double dz = p[2] - x_at_detection[3 * k + 2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 <= max_squared)) {  // also true for NaN
      if (std::isnan(d2)) return std::numeric_limits<double>::infinity();
      max_squared = d2;
    }
  }
  return std::sqrt(max_squared);
}

}  // namespace

double max_node_displacement(const double* x, const double* x_at_detection, LocalIndex n_nodes) {
  return largest_displacement(x, x_at_detection,
                              static_cast<std::size_t>(std::max<LocalIndex>(n_nodes, 0)),
                              [](std::size_t k) { return k; });
}

double max_node_displacement(const double* x, const double* x_at_detection, const LocalIndex* nodes,
                             std::size_t count) {
  return largest_displacement(x, x_at_detection, count,
                              [nodes](std::size_t k) { return nodes[k]; });
}

}  // namespace fdem
