// Stable time step of the mesh from element eigenvalues (see tet_critical_time_step).
#pragma once

#include "core/model.hpp"

namespace fdem {

struct CriticalStep {
  double dt = 0.0;  // s, the smallest element bound
  LocalIndex limiting_tet = -1;
};

// Uses the current positions (the tet's present shape and volume) with the small-strain stiffness.
CriticalStep critical_time_step(const Model& model);

}  // namespace fdem
