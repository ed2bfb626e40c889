// Broad phase of contact detection: which element pairs have overlapping (inflated) bounding
// boxes.  Shared pieces used by every algorithm (NBS in nbs.hpp, brute force and sort-and-sweep
// here) so that all of them return the identical, sorted list of candidate pairs:
//   - the inflated box of element i is [lo_i - buffer/2, hi_i + buffer/2] on every axis,
//     computed once by inflate_boxes() (same rounding for every algorithm);
//   - two inflated boxes overlap iff hi_a >= lo_b and hi_b >= lo_a on all three axes
//     (closed intervals: boxes that merely touch are candidates);
//   - a pair is stored as (a, b) with a < b, only if the optional filter keeps it;
//   - the output is sorted by a, then b.
#pragma once

#include <cstddef>
#include <type_traits>
#include <vector>

#include "core/types.hpp"

namespace fdem {

// A candidate contact pair of element indices, a < b.
struct CandidatePair {
  LocalIndex a;
  LocalIndex b;
  friend bool operator==(CandidatePair p, CandidatePair q) { return p.a == q.a && p.b == q.b; }
  friend bool operator!=(CandidatePair p, CandidatePair q) { return !(p == q); }
  friend bool operator<(CandidatePair p, CandidatePair q) {
    return p.a < q.a || (p.a == q.a && p.b < q.b);
  }
};

// Non-owning reference to a callable `bool(LocalIndex a, LocalIndex b)` (a < b) that returns
// true to keep a pair whose boxes overlap (e.g. false for two elements of the same body that
// share nodes, or that are bonded by an intact joint).  Default-constructed: keeps every pair.
// Use it only as a function parameter: it must not outlive the callable it refers to.
class PairFilter {
 public:
  PairFilter() = default;
  template <class F,
            class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, PairFilter> &&
                                     std::is_invocable_r_v<bool, F&, LocalIndex, LocalIndex>>>
  PairFilter(F&& f)  // NOLINT(google-explicit-constructor): implicit so lambdas pass directly
      : object_(const_cast<void*>(static_cast<const void*>(&f))),
        call_(&invoke<std::remove_reference_t<F>>) {}

  bool keep(LocalIndex a, LocalIndex b) const { return call_ == nullptr || call_(object_, a, b); }

 private:
  template <class F>
  static bool invoke(void* object, LocalIndex a, LocalIndex b) {
    return (*static_cast<F*>(object))(a, b);
  }
  void* object_ = nullptr;
  bool (*call_)(void*, LocalIndex, LocalIndex) = nullptr;
};

// Inflated boxes, 6 doubles per element: [lo_x, lo_y, lo_z, hi_x, hi_y, hi_z], each side moved
// out by buffer/2 (m).  lo, hi: 3*n doubles each (xyz per element).  Throws InputError for a
// negative or non-finite buffer or a box with lo > hi, NumericalFailure for non-finite
// coordinates (a run that blew up).
void inflate_boxes(const double* lo, const double* hi, LocalIndex n, double buffer,
                   std::vector<double>& boxes);
// The same for boxes given as 6 doubles per element [lo xyz, hi xyz], inflated in place (the same
// arithmetic and checks): a detection then holds one copy of the boxes, not two.
void inflate_boxes_in_place(std::vector<double>& boxes, LocalIndex n, double buffer);

// The one overlap predicate (closed boxes, 6 doubles each as produced by inflate_boxes).
// Bitwise & on purpose: all six comparisons, one hard-to-predict branch fewer per test.
inline bool boxes_overlap(const double* a, const double* b) {
  return (a[3] >= b[0]) & (b[3] >= a[0]) & (a[4] >= b[1]) & (b[4] >= a[1]) & (a[5] >= b[2]) &
         (b[5] >= a[2]);
}

// Sorts pairs by (a, b) (n = number of elements): a counting sort by a, then a sort of each
// element's partners by b; O(P + n) for bounded partners per element.  scratch and counts are
// reused workspace (pairs and scratch may exchange their buffers).
void sort_pairs(std::vector<CandidatePair>& pairs, LocalIndex n,
                std::vector<CandidatePair>& scratch, std::vector<std::size_t>& counts);

// Reference O(N^2): tests every pair.  out is cleared and filled, sorted.
void detect_brute_force(const double* lo, const double* hi, LocalIndex n, double buffer,
                        std::vector<CandidatePair>& out, PairFilter keep = {});

// Sort-and-sweep (sorting-based detection): sort the inflated boxes by their min coordinate
// along the axis of largest spread of box centres, then sweep: each box is tested against the
// following boxes while their min stays <= its max on that axis (the "active" boxes).
// O(N log N) for the sort plus the number of pairs overlapping along the sweep axis, which
// grows faster than N in 3D (about N^(5/3) for a cube-shaped cloud).  Workspace is reused.
class SortSweepDetector {
 public:
  void detect(const double* lo, const double* hi, LocalIndex n, double buffer,
              std::vector<CandidatePair>& out, PairFilter keep = {});
  // Bytes held by the reusable workspace (capacity), without the pair lists (output and its
  // sort scratch, 8 bytes per pair each).
  std::size_t workspace_bytes() const;
  // Overlap-predicate evaluations in the last detect() call.
  std::size_t box_tests() const { return box_tests_; }

 private:
  std::vector<double> boxes_;         // inflated boxes in input order
  std::vector<double> sorted_boxes_;  // the same, in sweep order
  std::vector<std::pair<double, LocalIndex>> order_;
  std::vector<CandidatePair> scratch_;
  std::vector<std::size_t> counts_;
  std::size_t box_tests_ = 0;
};

// Convenience wrapper around a temporary SortSweepDetector.
void detect_sort_sweep(const double* lo, const double* hi, LocalIndex n, double buffer,
                       std::vector<CandidatePair>& out, PairFilter keep = {});

}  // namespace fdem
