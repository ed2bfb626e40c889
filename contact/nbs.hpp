// Munjiza NBS (no binary search) contact detection in 3D (Munjiza, Owen & Bicanic 1995;
// Munjiza 2004, ch. 3), with a coarser level for elements much larger than the typical one.
//
// One level: space is cut into cubic cells of size d >= the largest inflated box extent of the
// level.  Each element goes to exactly one cell, the one holding the MIN corner of its inflated
// box.  The mapping is kept as singly linked lists in integer arrays ("head" sized by the number
// of cells along ONE axis, "next" sized by the number of elements):
//   layers (z) -> for the current layer and the one below, rows (y) -> for the current row and
//   its four half-stencil neighbour rows, cells (x).
// Every element of the current row is tested against the elements after it in its own cell and
// all elements of the 13 half-stencil neighbour cells (x-1 in its row; x-1..x+1 in row y-1;
// x-1..x+1 in rows y-1..y+1 of layer z-1), so every pair is tested exactly once.  Only
// non-empty layers and rows are visited and heads are reset by walking the lists again: there is
// no loop over cells, so time and memory are linear in N, whatever the domain size or packing
// density.
//
// Size disparity: if the largest extent exceeds size_ratio (2) x the smallest, d is 2x the
// median extent (when that is below the largest), otherwise the largest extent.  Elements larger
// than d are "large": they are tested against the level's elements whose cells their box covers
// (found through a row table or binary search in a cell-sorted copy of the level), and then form
// the next level, which repeats the same procedure among themselves.  Each level holds at least
// half of the remaining elements, so there are at most log2(N) levels; with similar sizes there
// is one.  See docs/contact-detection.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "contact/broad_phase.hpp"
#include "core/types.hpp"

namespace fdem {

struct NbsOptions {
  // Elements whose inflated extent exceeds size_ratio x the median extent of their level go to
  // the next, coarser level.  Must be >= 1.
  double size_ratio = 2.0;
  // > 0: use this cell size (m) for the first level instead of the automatic choice; elements
  // that do not fit in one cell go to the coarser levels.
  double cell_size = 0.0;
};

struct NbsLevelStats {
  LocalIndex elements = 0;                     // elements mapped at this level
  double cell_size = 0.0;                      // d (m)
  std::array<LocalIndex, 3> cells_per_axis{};  // extent of the head arrays (x, y, z)
  std::int64_t occupied_cells = 0;             // non-empty cells
};

struct NbsStats {
  LocalIndex elements = 0;
  LocalIndex large_elements = 0;  // elements not mapped at the first level
  std::vector<NbsLevelStats> levels;
  std::size_t box_tests = 0;  // overlap-predicate evaluations
  std::size_t pairs = 0;      // candidate pairs returned
  // Capacity of the reusable arrays, without the pair lists (output and its sort scratch,
  // 8 bytes per pair each).
  std::size_t workspace_bytes = 0;
};

class NbsDetector {
 public:
  explicit NbsDetector(NbsOptions options = {});

  // lo, hi: 3*n doubles (xyz per element) of the element bounding boxes (m).  Each box is
  // inflated by buffer/2 (m) per side.  out is cleared and filled with the pairs (a < b) of
  // overlapping inflated boxes that keep() accepts, sorted by a then b.
  void detect(const double* lo, const double* hi, LocalIndex n, double buffer,
              std::vector<CandidatePair>& out, PairFilter keep = {});
  // The same with the boxes as 6 doubles per element [lo xyz, hi xyz], taken over (moved from)
  // and inflated in place: the caller's copy is the detector's, none is made.
  void detect(std::vector<double>&& boxes, LocalIndex n, double buffer,
              std::vector<CandidatePair>& out, PairFilter keep = {});

  const NbsStats& stats() const { return stats_; }
  std::size_t workspace_bytes() const;
  // Gives the grids and scratch arrays back (the next detect() rebuilds them).
  void release_workspace();

 private:
  // The search over boxes_ (inflated, 6 doubles per element).
  void detect_inflated(LocalIndex n, std::vector<CandidatePair>& out, PairFilter keep);
  struct Level {
    std::vector<LocalIndex> ids;     // global element index of each local element
    std::vector<std::int32_t> cell;  // 3 per local element: x, y, z cell index (1-based)
    std::vector<LocalIndex> next_in_layer, next_in_row, next_in_cell;
    std::vector<LocalIndex> head_layer, head_row_current, head_row_below;
    std::array<std::vector<LocalIndex>, 5> head_cell;  // this row and its 4 half-stencil rows
    std::vector<LocalIndex> used_layers, used_rows;
    std::vector<LocalIndex> by_cell;  // local elements sorted by (z, y, x), for large elements
    std::vector<LocalIndex> by_cell_scratch;
    std::vector<LocalIndex> counts;  // counting sort; then the row table (end of each row)
    std::array<double, 3> origin{};
    double inverse_cell_size = 0.0;
    std::array<std::int32_t, 3> n_cells{};
    std::size_t bytes() const;
  };

  void map_level(Level& level, double cell_size, NbsLevelStats& level_stats);
  void sweep_level(Level& level, std::vector<CandidatePair>& out, PairFilter keep,
                   NbsLevelStats& level_stats);
  void test_large_against_level(Level& level, const std::vector<LocalIndex>& large,
                                std::vector<CandidatePair>& out, PairFilter keep);

  NbsOptions options_;
  NbsStats stats_;
  std::vector<Level> levels_;
  std::vector<double> boxes_;
  std::vector<double> extent_, extent_scratch_;
  std::vector<LocalIndex> remaining_, large_;
  std::vector<CandidatePair> scratch_;
  std::vector<std::size_t> counts_;
  bool heads_clean_ = true;  // all head arrays hold -1 (false after an interrupted call)
};

}  // namespace fdem
