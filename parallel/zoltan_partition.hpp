// Re-partition by space with Zoltan (Sandia's load-balancing library): weighted recursive
// bisection of points spread over all ranks, each rank passing only its own points — no rank
// gathers the whole model.  Used at contact-detection cycles (parallel/distribution).
#pragma once

#include <cstdint>
#include <vector>

#include "core/types.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

struct PartitionPoint {
  GlobalId gid;
  double x[3];    // m (a tet's centroid)
  double weight;  // cost, in any unit (≥ 0)
};

enum class GeometricMethod {
  rib,  // recursive inertial bisection: cuts across the axis of largest weighted spread
  rcb,  // recursive coordinate bisection: cuts across the longest coordinate extent
  // Hilbert space-filling curve: parts are stretches of the curve, found from global histograms
  // (reductions of O(P) numbers); no point moves while partitioning, unlike RIB/RCB, whose
  // recursion moves every point log2(P) times.
  hsfc,
};

// Collective: the new part (a rank, 0 … size−1) of each of this rank's points, in input order.
// Every rank may pass any number of points (also none).
std::vector<std::int32_t> partition_geometric(const std::vector<PartitionPoint>& points,
                                              const Communicator& comm,
                                              GeometricMethod method = GeometricMethod::rib);

}  // namespace fdem
