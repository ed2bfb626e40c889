// Pairs apart by a known gap stay apart until their tets have moved that far.  A candidate pair
// found apart with a gap g (its boxes, a face plane or an edge–edge axis: m, less a margin above
// round-off) is not evaluated again while the corners of its two tets have travelled less than g
// in all since: every point of a tet moves at most as far as its farthest corner (a point is a
// fixed convex combination of the corners), so the two tets close the gap by at most the sum of
// their corners' largest travels, and the plane that separated them still does.  The kernel
// would find such a pair apart too (its clip of tets a margin apart finds no volume), so skipping
// it changes no result, bit for bit.  Travel is measured from the corners the contact stage sees
// at each step, whatever moved them (integration, a halo update, a prescribed motion).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "contact/tet_overlap.hpp"

namespace fdem {

class ApartPairs {
 public:
  // A new list of pair tets (`tets` of them) and pairs: no travel and no gap known.
  void reset(std::size_t tets) {
    travel_.assign(tets, 0.0);
    gap_end_.clear();
    gap_end_.shrink_to_fit();
  }
  // The corners of pair tet `slot` went from `before` to `after` (m).  The sum stays an upper
  // bound of the travel: each increment is rounded up by far more than its round-off, and the
  // running sum by more than one unit in its last place.
  void moved(std::size_t slot, const TetCorners& before, const TetCorners& after) {
    double largest = 0.0;
    bool finite = true;
    for (int c = 0; c < 4; ++c) {
      const double squared = (after.x[c] - before.x[c]).squaredNorm();
      finite &= squared <= kFar;
      largest = std::max(largest, squared);
    }
    if (!finite) largest = kFar;  // NaN or huge: no pair of this tet is skipped again
    double& travel = travel_[slot];
    travel += std::sqrt(largest) * (1.0 + 1e-9) + travel * 1e-15;
  }
  // Whether pair `pair` (its tets at slots a, b) is sure to be still apart.
  bool still_apart(std::size_t pair, std::int32_t a, std::int32_t b) const {
    return pair < gap_end_.size() && travel_[a] + travel_[b] < gap_end_[pair];
  }
  // Pair `pair` of `pairs` was found apart by at least `gap` (m, > 0), or (gap 0) it was not.
  void found(std::size_t pair, std::size_t pairs, std::int32_t a, std::int32_t b, double gap) {
    if (!(gap > 0.0)) {
      if (pair < gap_end_.size()) gap_end_[pair] = 0.0;
      return;
    }
    if (gap_end_.size() != pairs) gap_end_.assign(pairs, 0.0);
    // Each term shrunk by far more than the round-off of the sums here and in still_apart.
    gap_end_[pair] = gap * (1.0 - 1e-12) + (travel_[a] + travel_[b]) * (1.0 - 1e-15);
  }
  // Where the pair list is dropped until the next one (release_until_rebind).
  void release() {
    std::vector<double>().swap(travel_);
    std::vector<double>().swap(gap_end_);
  }

 private:
  static constexpr double kFar = 1e200;  // m², a squared travel beyond any gap
  std::vector<double> travel_;   // per pair tet: Σ of its corners' largest travel per step (m)
  std::vector<double> gap_end_;  // per pair: gap + both tets' travel when it was found apart (m)
};

// The gap (m) by which two boxes lie apart; 0 where they meet.
inline double box_gap(const TetBox& a, const TetBox& b) {
  double gap = 0.0;
  for (int k = 0; k < 3; ++k) gap = std::max(gap, std::max(b.lo[k] - a.hi[k], a.lo[k] - b.hi[k]));
  return gap;
}

}  // namespace fdem
