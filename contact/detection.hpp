// When to re-run contact detection (the buffer rule).  Detection inflates every element box by
// buffer/2 per side, so the candidate list stays complete while no node has moved more than
// buffer/2 since the last detection: two current boxes can only overlap if the boxes at
// detection, each grown by the largest node travel, overlap.
#pragma once

#include <cstddef>

#include "core/types.hpp"

namespace fdem {

// True when the largest node travel since the last detection (m) has used up half the buffer (m).
inline bool detection_needed(double max_travel, double buffer) {
  return max_travel > 0.5 * buffer;
}

// Largest Euclidean node displacement (m) between x and x_at_detection (3*n_nodes doubles
// each, xyz per node).  0 for n_nodes == 0.  A NaN displacement is returned as +infinity so
// that the caller always re-detects (and the detector then reports the non-finite box).
double max_node_displacement(const double* x, const double* x_at_detection, LocalIndex n_nodes);
// The same over the listed nodes only: x_at_detection holds 3 values per listed node, in order.
double max_node_displacement(const double* x, const double* x_at_detection, const LocalIndex* nodes,
                             std::size_t count);

}  // namespace fdem
