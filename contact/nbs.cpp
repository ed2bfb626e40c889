#include "contact/nbs.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <string>

#include "core/error.hpp"

namespace fdem {

namespace {

constexpr LocalIndex kEmpty = -1;
// Cells per axis are capped (so a few far-away outliers cannot blow up the head arrays); the
// cell size grows instead, which keeps the search correct.  2^20 also keeps the int64 cell key
// (z, y, x) of the large-element pass free of overflow.
constexpr std::int32_t kMaxCellsPerAxis = 1 << 20;

template <class T>
std::size_t capacity_bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

// Grows v to at least size entries, new entries kEmpty (existing ones are kEmpty by invariant).
void ensure_heads(std::vector<LocalIndex>& v, std::size_t size) {
  if (v.size() < size) v.resize(size, kEmpty);
}

}  // namespace

NbsDetector::NbsDetector(NbsOptions options) : options_(options) {
  if (!(options_.size_ratio >= 1.0) || !std::isfinite(options_.size_ratio)) {
    throw InputError("NBS contact detection: size_ratio must be >= 1, got " +
                     std::to_string(options_.size_ratio) + ".");
  }
  if (!(options_.cell_size >= 0.0) || !std::isfinite(options_.cell_size)) {
    throw InputError("NBS contact detection: cell_size must be >= 0 (m; 0 = automatic), got " +
                     std::to_string(options_.cell_size) + ".");
  }
}

std::size_t NbsDetector::Level::bytes() const {
  std::size_t total = capacity_bytes(ids) + capacity_bytes(cell) + capacity_bytes(next_in_layer) +
                      capacity_bytes(next_in_row) + capacity_bytes(next_in_cell) +
                      capacity_bytes(head_layer) + capacity_bytes(head_row_current) +
                      capacity_bytes(head_row_below) + capacity_bytes(used_layers) +
                      capacity_bytes(used_rows) + capacity_bytes(by_cell) +
                      capacity_bytes(by_cell_scratch) + capacity_bytes(counts);
  for (const auto& h : head_cell) total += capacity_bytes(h);
  return total;
}

std::size_t NbsDetector::workspace_bytes() const {
  std::size_t total = capacity_bytes(boxes_) + capacity_bytes(extent_) +
                      capacity_bytes(extent_scratch_) + capacity_bytes(remaining_) +
                      capacity_bytes(large_) + capacity_bytes(counts_);
  for (const Level& level : levels_) total += level.bytes();
  return total;
}

void NbsDetector::release_workspace() {
  release(levels_);  // head arrays are built afresh (all −1) for new levels
  release(boxes_);
  release(extent_);
  release(extent_scratch_);
  release(remaining_);
  release(large_);
  release(scratch_);
  release(counts_);
  heads_clean_ = true;
}

void NbsDetector::detect(const double* lo, const double* hi, LocalIndex n, double buffer,
                         std::vector<CandidatePair>& out, PairFilter keep) {
  inflate_boxes(lo, hi, n, buffer, boxes_);
  detect_inflated(n, out, keep);
}

void NbsDetector::detect(std::vector<double>&& boxes, LocalIndex n, double buffer,
                         std::vector<CandidatePair>& out, PairFilter keep) {
  boxes_ = std::move(boxes);
  inflate_boxes_in_place(boxes_, n, buffer);
  detect_inflated(n, out, keep);
}

void NbsDetector::detect_inflated(LocalIndex n, std::vector<CandidatePair>& out, PairFilter keep) {
  out.clear();
  stats_ = NbsStats{};
  stats_.elements = n;
  if (!heads_clean_) {  // a previous call was interrupted (e.g. the filter threw)
    for (Level& level : levels_) {
      std::fill(level.head_layer.begin(), level.head_layer.end(), kEmpty);
      std::fill(level.head_row_current.begin(), level.head_row_current.end(), kEmpty);
      std::fill(level.head_row_below.begin(), level.head_row_below.end(), kEmpty);
      for (auto& h : level.head_cell) std::fill(h.begin(), h.end(), kEmpty);
      level.used_layers.clear();
      level.used_rows.clear();
    }
  }
  heads_clean_ = false;

  // Inflated extent of each element (largest side) and the coordinate magnitude, which sets
  // the round-off margin of the cell size.
  extent_.resize(n);
  double max_abs_coordinate = 0.0;
  for (LocalIndex i = 0; i < n; ++i) {
    const double* box = &boxes_[6 * i];
    const double ex = box[3] - box[0], ey = box[4] - box[1], ez = box[5] - box[2];
    extent_[i] = std::max(ex, std::max(ey, ez));
    // lo <= hi, so max(|lo|, |hi|) = max(-lo, hi) on each axis.
    const double ax = std::max(-box[0], box[3]), ay = std::max(-box[1], box[4]),
                 az = std::max(-box[2], box[5]);
    max_abs_coordinate = std::max(max_abs_coordinate, std::max(ax, std::max(ay, az)));
  }
  // A box whose extent is below d - margin provably cannot reach past the neighbour cell, even
  // with the round-off of the cell index (relative 1e-6 of d, or 64 ulp of the coordinates).
  const double absolute_margin = 64.0 * DBL_EPSILON * max_abs_coordinate;
  auto margin = [&](double size) { return std::max(1e-6 * size, absolute_margin); };

  remaining_.resize(n);
  std::iota(remaining_.begin(), remaining_.end(), 0);
  std::size_t level_index = 0;
  while (!remaining_.empty()) {
    if (levels_.size() <= level_index) levels_.emplace_back();
    Level& level = levels_[level_index];
    const std::size_t m = remaining_.size();

    double limit = 0.0;  // largest extent mapped at this level
    double cell_size = 0.0;
    if (level_index == 0 && options_.cell_size > 0.0) {
      cell_size = options_.cell_size;
      limit = cell_size - margin(cell_size);
    } else {
      double min_extent = extent_[remaining_[0]], max_extent = min_extent;
      for (LocalIndex g : remaining_) {
        min_extent = std::min(min_extent, extent_[g]);
        max_extent = std::max(max_extent, extent_[g]);
      }
      limit = max_extent;
      if (max_extent > options_.size_ratio * min_extent) {  // else nothing can be large
        extent_scratch_.resize(m);
        for (std::size_t k = 0; k < m; ++k) extent_scratch_[k] = extent_[remaining_[k]];
        auto middle = extent_scratch_.begin() + static_cast<std::ptrdiff_t>(m / 2);
        std::nth_element(extent_scratch_.begin(), middle, extent_scratch_.end());
        const double median_limit = options_.size_ratio * *middle;
        if (median_limit > 0.0 && median_limit < max_extent) limit = median_limit;
      }
      cell_size = limit + margin(limit);
    }

    level.ids.clear();
    large_.clear();
    for (LocalIndex g : remaining_) {
      if (extent_[g] <= limit) {
        level.ids.push_back(g);
      } else {
        large_.push_back(g);
      }
    }

    NbsLevelStats level_stats;
    level_stats.elements = static_cast<LocalIndex>(level.ids.size());
    if (!level.ids.empty()) {
      map_level(level, cell_size, level_stats);
      sweep_level(level, out, keep, level_stats);
      if (!large_.empty()) test_large_against_level(level, large_, out, keep);
    }
    stats_.levels.push_back(level_stats);
    if (level_index == 0) stats_.large_elements = static_cast<LocalIndex>(large_.size());
    remaining_.swap(large_);
    ++level_index;
  }

  sort_pairs(out, n, scratch_, counts_);
  stats_.pairs = out.size();
  stats_.workspace_bytes = workspace_bytes();
  heads_clean_ = true;
}

void NbsDetector::map_level(Level& level, double cell_size, NbsLevelStats& level_stats) {
  const std::size_t m = level.ids.size();
  std::array<double, 3> min_corner, max_corner;
  for (int k = 0; k < 3; ++k) {
    min_corner[k] = max_corner[k] = boxes_[6 * level.ids[0] + k];
  }
  for (LocalIndex g : level.ids) {
    for (int k = 0; k < 3; ++k) {
      min_corner[k] = std::min(min_corner[k], boxes_[6 * g + k]);
      max_corner[k] = std::max(max_corner[k], boxes_[6 * g + k]);
    }
  }
  double max_span = 0.0;
  for (int k = 0; k < 3; ++k) max_span = std::max(max_span, max_corner[k] - min_corner[k]);
  // Non-finite boxes would make the cell counts below undefined casts; the driver's state check
  // stops a run with NaN or infinite positions before they reach detection.
  FDEM_VERIFY(std::isfinite(max_span), "contact detection over non-finite element boxes");
  if (!(cell_size > 0.0)) {  // every box is a point: any positive size works
    cell_size = max_span > 0.0 ? max_span / std::max(1.0, std::cbrt(static_cast<double>(m))) : 1.0;
  }
  const double cap =
      static_cast<double>(std::min<std::size_t>(std::max<std::size_t>(64, m), kMaxCellsPerAxis));
  if (max_span / cell_size > cap - 2.0) cell_size = max_span / (cap - 2.0);

  level.origin = min_corner;
  level.inverse_cell_size = 1.0 / cell_size;
  for (int k = 0; k < 3; ++k) {
    level.n_cells[k] = static_cast<std::int32_t>(
                           std::floor((max_corner[k] - min_corner[k]) * level.inverse_cell_size)) +
                       1;
  }
  level_stats.cell_size = cell_size;
  level_stats.cells_per_axis = {level.n_cells[0], level.n_cells[1], level.n_cells[2]};

  // Cell of each element: the one holding the min corner of its inflated box, 1-based so the
  // neighbours x-1 and x+1 of every occupied cell are valid head-array entries.
  level.cell.resize(3 * m);
  for (std::size_t k = 0; k < m; ++k) {
    const double* box = &boxes_[6 * level.ids[k]];
    for (int a = 0; a < 3; ++a) {
      // box[a] >= origin, so truncation is floor (and avoids a libm call).
      const double t = (box[a] - level.origin[a]) * level.inverse_cell_size;
      level.cell[3 * k + a] =
          static_cast<std::int32_t>(std::min<double>(t, level.n_cells[a] - 1)) + 1;
    }
  }
  level.next_in_layer.resize(m);
  level.next_in_row.resize(m);
  level.next_in_cell.resize(m);
  ensure_heads(level.head_layer, level.n_cells[2] + 2);
  ensure_heads(level.head_row_current, level.n_cells[1] + 2);
  ensure_heads(level.head_row_below, level.n_cells[1] + 2);
  for (auto& h : level.head_cell) ensure_heads(h, level.n_cells[0] + 2);
}

void NbsDetector::sweep_level(Level& level, std::vector<CandidatePair>& out, PairFilter keep,
                              NbsLevelStats& level_stats) {
  const LocalIndex m = static_cast<LocalIndex>(level.ids.size());
  const std::int32_t* cell = level.cell.data();
  const LocalIndex* ids = level.ids.data();
  const double* boxes = boxes_.data();
  LocalIndex* next_in_layer = level.next_in_layer.data();
  LocalIndex* next_in_row = level.next_in_row.data();
  LocalIndex* next_in_cell = level.next_in_cell.data();
  LocalIndex* head_layer = level.head_layer.data();
  LocalIndex* head_row_current = level.head_row_current.data();
  LocalIndex* head_row_below = level.head_row_below.data();
  LocalIndex* head_cell[5];
  for (int r = 0; r < 5; ++r) head_cell[r] = level.head_cell[r].data();
  std::size_t tests = 0;
  std::int64_t occupied = 0;

  // Stage 1: layers (z).
  level.used_layers.clear();
  for (LocalIndex k = 0; k < m; ++k) {
    const std::int32_t z = cell[3 * k + 2];
    if (head_layer[z] == kEmpty) level.used_layers.push_back(z);
    next_in_layer[k] = head_layer[z];
    head_layer[z] = k;
  }

  for (const LocalIndex z : level.used_layers) {
    // Stage 2: rows (y) of this layer and of the layer below.
    level.used_rows.clear();
    for (LocalIndex k = head_layer[z]; k != kEmpty; k = next_in_layer[k]) {
      const std::int32_t y = cell[3 * k + 1];
      if (head_row_current[y] == kEmpty) level.used_rows.push_back(y);
      next_in_row[k] = head_row_current[y];
      head_row_current[y] = k;
    }
    const bool below = head_layer[z - 1] != kEmpty;
    for (LocalIndex k = head_layer[z - 1]; k != kEmpty; k = next_in_layer[k]) {
      const std::int32_t y = cell[3 * k + 1];
      next_in_row[k] = head_row_below[y];
      head_row_below[y] = k;
    }

    for (const LocalIndex y : level.used_rows) {
      // Stage 3: cells (x) of this row and its half-stencil rows.
      const LocalIndex rows[5] = {
          head_row_current[y], head_row_current[y - 1], below ? head_row_below[y - 1] : kEmpty,
          below ? head_row_below[y] : kEmpty, below ? head_row_below[y + 1] : kEmpty};
      for (int r = 0; r < 5; ++r) {
        LocalIndex* heads = head_cell[r];
        for (LocalIndex k = rows[r]; k != kEmpty; k = next_in_row[k]) {
          const std::int32_t x = cell[3 * k];
          if (r == 0 && heads[x] == kEmpty) ++occupied;
          next_in_cell[k] = heads[x];
          heads[x] = k;
        }
      }
      for (LocalIndex k = rows[0]; k != kEmpty; k = next_in_row[k]) {
        const std::int32_t x = cell[3 * k];
        // The lists to test k against: later elements of its own cell, x-1 in its row, and
        // x-1..x+1 in each non-empty half-stencil row (at most 14 lists).
        LocalIndex lists[14];
        int n_lists = 0;
        lists[n_lists++] = next_in_cell[k];
        lists[n_lists++] = head_cell[0][x - 1];
        for (int r = 1; r < 5; ++r) {
          if (rows[r] == kEmpty) continue;
          lists[n_lists++] = head_cell[r][x - 1];
          lists[n_lists++] = head_cell[r][x];
          lists[n_lists++] = head_cell[r][x + 1];
        }
        const LocalIndex id_k = ids[k];
        const double* box_k = boxes + 6 * id_k;
        for (int l = 0; l < n_lists; ++l) {
          for (LocalIndex j = lists[l]; j != kEmpty; j = next_in_cell[j]) {
            ++tests;
            const LocalIndex id_j = ids[j];
            if (boxes_overlap(box_k, boxes + 6 * id_j)) {
              const LocalIndex a = std::min(id_k, id_j), b = std::max(id_k, id_j);
              if (keep.keep(a, b)) out.push_back({a, b});
            }
          }
        }
      }
      for (int r = 0; r < 5; ++r) {  // reset the cell heads by walking the rows again
        for (LocalIndex k = rows[r]; k != kEmpty; k = next_in_row[k])
          head_cell[r][cell[3 * k]] = kEmpty;
      }
    }

    for (const LocalIndex y : level.used_rows) head_row_current[y] = kEmpty;
    for (LocalIndex k = head_layer[z - 1]; k != kEmpty; k = next_in_layer[k]) {
      head_row_below[cell[3 * k + 1]] = kEmpty;
    }
  }
  for (const LocalIndex z : level.used_layers) head_layer[z] = kEmpty;
  level.used_layers.clear();
  level.used_rows.clear();

  stats_.box_tests += tests;
  level_stats.occupied_cells = occupied;
}

void NbsDetector::test_large_against_level(Level& level, const std::vector<LocalIndex>& large,
                                           std::vector<CandidatePair>& out, PairFilter keep) {
  const LocalIndex m = static_cast<LocalIndex>(level.ids.size());
  const std::int32_t* cell = level.cell.data();
  const std::int64_t nx = level.n_cells[0] + 2, ny = level.n_cells[1] + 2,
                     nz = level.n_cells[2] + 2;
  auto key_of = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (z * ny + y) * nx + x;
  };
  auto key = [&](LocalIndex k) { return key_of(cell[3 * k], cell[3 * k + 1], cell[3 * k + 2]); };

  // Local elements sorted by cell (z, y, x) with stable counting-sort passes: by x, then by
  // row (z, y) when a table with one entry per row stays within O(m) memory (the usual case:
  // about m^(2/3) rows), else by y and then z.  O(m + cells along the axes or rows).
  const std::int64_t n_rows = ny * nz;
  const bool row_table = n_rows <= 4 * static_cast<std::int64_t>(m) + 4096;
  level.by_cell.resize(m);
  std::vector<LocalIndex>& order = level.by_cell;
  std::vector<LocalIndex>& pass = level.by_cell_scratch;
  pass.resize(m);
  std::iota(pass.begin(), pass.end(), 0);
  auto counting_pass = [&](std::size_t n_keys, auto&& key_of_element) {
    level.counts.assign(n_keys + 1, 0);
    for (LocalIndex k : pass) ++level.counts[key_of_element(k) + 1];
    for (std::size_t c = 1; c < level.counts.size(); ++c) level.counts[c] += level.counts[c - 1];
    for (LocalIndex k : pass) order[level.counts[key_of_element(k)]++] = k;
    pass.swap(order);  // the sorted order is now in `pass`
  };
  counting_pass(static_cast<std::size_t>(nx), [&](LocalIndex k) { return cell[3 * k]; });
  if (row_table) {
    // After this pass counts[r] is the end of row r = the start of row r + 1.
    counting_pass(static_cast<std::size_t>(n_rows),
                  [&](LocalIndex k) { return cell[3 * k + 2] * ny + cell[3 * k + 1]; });
  } else {
    counting_pass(static_cast<std::size_t>(ny), [&](LocalIndex k) { return cell[3 * k + 1]; });
    counting_pass(static_cast<std::size_t>(nz), [&](LocalIndex k) { return cell[3 * k + 2]; });
  }
  order.swap(pass);
  const LocalIndex* sorted = order.data();

  auto cell_of = [&](double v, int a) {
    double t = std::floor((v - level.origin[a]) * level.inverse_cell_size);
    t = std::max(-1.0, std::min<double>(t, level.n_cells[a]));
    return static_cast<std::int32_t>(t) + 1;
  };

  const double log_m = std::log2(static_cast<double>(m) + 1.0);
  std::size_t tests = 0;
  for (const LocalIndex g : large) {
    const double* box_g = &boxes_[6 * g];
    std::int32_t first[3], last[3];
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      // A level element overlapping box_g has its min corner within [lo_g - d, hi_g].
      first[a] = std::max(1, cell_of(box_g[a], a) - 1);
      last[a] = std::min(level.n_cells[a], cell_of(box_g[3 + a], a));
      empty = empty || first[a] > last[a];
    }
    if (empty) continue;
    auto test = [&](LocalIndex k) {
      ++tests;
      if (boxes_overlap(box_g, &boxes_[6 * level.ids[k]])) {
        const LocalIndex a = std::min(g, level.ids[k]), b = std::max(g, level.ids[k]);
        if (keep.keep(a, b)) out.push_back({a, b});
      }
    };
    // Scans positions [begin, end) of one row (sorted by x) for cells first[0]..last[0].
    auto scan_row = [&](std::size_t begin, std::size_t end) {
      if (end - begin > 16) {
        begin = static_cast<std::size_t>(
            std::partition_point(sorted + begin, sorted + end,
                                 [&](LocalIndex k) { return cell[3 * k] < first[0]; }) -
            sorted);
      }
      for (std::size_t p = begin; p < end; ++p) {
        const std::int32_t x = cell[3 * sorted[p]];
        if (x > last[0]) break;
        if (x >= first[0]) test(sorted[p]);
      }
    };
    if (row_table) {
      for (std::int32_t z = first[2]; z <= last[2]; ++z) {
        for (std::int32_t y = first[1]; y <= last[1]; ++y) {
          const std::int64_t r = z * ny + y;
          scan_row(r > 0 ? level.counts[r - 1] : 0, level.counts[r]);
        }
      }
      continue;
    }
    auto lower_bound = [&](std::int64_t target) {
      return static_cast<std::size_t>(
          std::partition_point(sorted, sorted + m, [&](LocalIndex k) { return key(k) < target; }) -
          sorted);
    };
    const double rows = static_cast<double>(last[1] - first[1] + 1) * (last[2] - first[2] + 1);
    if (rows * log_m > m) {
      // Box covers more rows than the level has elements: one scan of the covered key range.
      const std::int64_t end_key = key_of(last[0], last[1], last[2]);
      for (std::size_t p = lower_bound(key_of(first[0], first[1], first[2]));
           p < static_cast<std::size_t>(m) && key(sorted[p]) <= end_key; ++p) {
        const std::int32_t* c = &cell[3 * sorted[p]];
        if (c[0] >= first[0] && c[0] <= last[0] && c[1] >= first[1] && c[1] <= last[1]) {
          test(sorted[p]);
        }
      }
    } else {
      for (std::int32_t z = first[2]; z <= last[2]; ++z) {
        for (std::int32_t y = first[1]; y <= last[1]; ++y) {
          const std::int64_t end_key = key_of(last[0], y, z);
          for (std::size_t p = lower_bound(key_of(first[0], y, z));
               p < static_cast<std::size_t>(m) && key(sorted[p]) <= end_key; ++p) {
            test(sorted[p]);
          }
        }
      }
    }
  }
  stats_.box_tests += tests;
}

}  // namespace fdem
