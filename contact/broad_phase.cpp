#include "contact/broad_phase.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace fdem {

void inflate_boxes_in_place(std::vector<double>& boxes, LocalIndex n, double buffer) {
  if (!(buffer >= 0.0) || !std::isfinite(buffer)) {
    throw InputError("contact detection: the buffer must be a finite distance >= 0 (m), got " +
                     std::to_string(buffer) + ".");
  }
  if (n < 0) throw InputError("contact detection: negative element count.");
  FDEM_VERIFY(boxes.size() == 6 * static_cast<std::size_t>(n), "6 doubles per box");
  const double half = 0.5 * buffer;
  for (LocalIndex i = 0; i < n; ++i) {
    double* box = boxes.data() + 6 * static_cast<std::size_t>(i);
    for (int k = 0; k < 3; ++k) {
      const double l = box[k];
      const double h = box[3 + k];
      if (!std::isfinite(l) || !std::isfinite(h)) {
        throw NumericalFailure("contact detection: element " + std::to_string(i) +
                               " has a non-finite bounding box (its nodes left the finite range); "
                               "reduce the time step or check the loads.");
      }
      if (l > h) {
        throw InputError("contact detection: element " + std::to_string(i) +
                         " has a bounding box with min > max on axis " + std::to_string(k) + ".");
      }
      box[k] = l - half;
      box[3 + k] = h + half;
    }
  }
}

void inflate_boxes(const double* lo, const double* hi, LocalIndex n, double buffer,
                   std::vector<double>& boxes) {
  boxes.resize(6 * static_cast<std::size_t>(std::max<LocalIndex>(n, 0)));
  for (LocalIndex i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      boxes[6 * static_cast<std::size_t>(i) + k] = lo[3 * i + k];
      boxes[6 * static_cast<std::size_t>(i) + 3 + k] = hi[3 * i + k];
    }
  inflate_boxes_in_place(boxes, n, buffer);
}

void sort_pairs(std::vector<CandidatePair>& pairs, LocalIndex n,
                std::vector<CandidatePair>& scratch, std::vector<std::size_t>& counts) {
  const std::size_t p = pairs.size();
  if (p < 2) return;
  // One stable counting-sort pass by a into scratch (O(P + n)), then each bucket (the partners
  // of one element: a few to a few hundred pairs, contiguous in memory) is sorted by b.
  scratch.resize(p);
  counts.assign(static_cast<std::size_t>(n) + 1, 0);
  for (const CandidatePair& q : pairs) ++counts[q.a + 1];
  for (LocalIndex i = 0; i < n; ++i) counts[i + 1] += counts[i];
  for (const CandidatePair& q : pairs) scratch[counts[q.a]++] = q;
  std::size_t begin = 0;
  for (LocalIndex i = 0; i < n; ++i) {
    const std::size_t end = counts[i];
    if (end - begin > 1) {
      std::sort(scratch.begin() + static_cast<std::ptrdiff_t>(begin),
                scratch.begin() + static_cast<std::ptrdiff_t>(end),
                [](CandidatePair x, CandidatePair y) { return x.b < y.b; });
    }
    begin = end;
  }
  pairs.swap(scratch);
}

void detect_brute_force(const double* lo, const double* hi, LocalIndex n, double buffer,
                        std::vector<CandidatePair>& out, PairFilter keep) {
  std::vector<double> boxes;
  inflate_boxes(lo, hi, n, buffer, boxes);
  out.clear();
  for (LocalIndex a = 0; a < n; ++a) {
    const double* box_a = &boxes[6 * a];
    for (LocalIndex b = a + 1; b < n; ++b) {
      if (boxes_overlap(box_a, &boxes[6 * b]) && keep.keep(a, b)) out.push_back({a, b});
    }
  }
}

void SortSweepDetector::detect(const double* lo, const double* hi, LocalIndex n, double buffer,
                               std::vector<CandidatePair>& out, PairFilter keep) {
  inflate_boxes(lo, hi, n, buffer, boxes_);
  out.clear();
  box_tests_ = 0;
  if (n < 2) return;

  // Sweep axis: largest spread of box centres (fewest boxes overlap along it).
  int axis = 0;
  double best_spread = -1.0;
  for (int k = 0; k < 3; ++k) {
    double cmin = boxes_[k] + boxes_[3 + k], cmax = cmin;
    for (LocalIndex i = 1; i < n; ++i) {
      const double c = boxes_[6 * i + k] + boxes_[6 * i + 3 + k];
      cmin = std::min(cmin, c);
      cmax = std::max(cmax, c);
    }
    if (cmax - cmin > best_spread) {
      best_spread = cmax - cmin;
      axis = k;
    }
  }

  order_.resize(n);
  for (LocalIndex i = 0; i < n; ++i) order_[i] = {boxes_[6 * i + axis], i};
  std::sort(order_.begin(), order_.end());
  // Copy boxes into sweep order so the inner loop reads memory sequentially.
  sorted_boxes_.resize(6 * static_cast<std::size_t>(n));
  for (LocalIndex p = 0; p < n; ++p) {
    std::copy_n(&boxes_[6 * order_[p].second], 6, &sorted_boxes_[6 * p]);
  }

  std::size_t tests = 0;
  for (LocalIndex p = 0; p < n; ++p) {
    const double* box_p = &sorted_boxes_[6 * p];
    const double max_on_axis = box_p[3 + axis];
    const LocalIndex id_p = order_[p].second;
    for (LocalIndex q = p + 1; q < n && order_[q].first <= max_on_axis; ++q) {
      ++tests;
      if (boxes_overlap(box_p, &sorted_boxes_[6 * q])) {
        const LocalIndex id_q = order_[q].second;
        const LocalIndex a = std::min(id_p, id_q), b = std::max(id_p, id_q);
        if (keep.keep(a, b)) out.push_back({a, b});
      }
    }
  }
  box_tests_ = tests;
  sort_pairs(out, n, scratch_, counts_);
}

std::size_t SortSweepDetector::workspace_bytes() const {
  return boxes_.capacity() * sizeof(double) + sorted_boxes_.capacity() * sizeof(double) +
         order_.capacity() * sizeof(order_[0]) + counts_.capacity() * sizeof(std::size_t);
}

void detect_sort_sweep(const double* lo, const double* hi, LocalIndex n, double buffer,
                       std::vector<CandidatePair>& out, PairFilter keep) {
  SortSweepDetector detector;
  detector.detect(lo, hi, n, buffer, out, keep);
}

}  // namespace fdem
