// How far below the sliver limit the pieces a pair keeps really are: for the pairs that carry load
// in a scene, what each kept piece contributes to the nodal forces against what its bound says and
// against the limit under which it would be left out (contact/pair_force_bound.hpp).
//
//   bench_contact_piece_margins SCENE.yaml TIME [--set key=value ...]
//
// The scene runs (one rank, no output) to TIME.  For each candidate pair that overlaps and is not
// left out whole: the pieces kept under the scene's sliver tolerance; per side the piece that
// contributes most ("main"); for every other kept piece, its contribution (the largest change of
// a nodal force when it alone is also left out, with its flux: potential_contact_without) and its
// bound, both over the limit.  A piece whose contribution is far below the limit but whose bound
// is not is one a tighter bound would leave out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "contact/pair_force_bound.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_overlap.hpp"
#include "drivers/simulation.hpp"
#include "io/scene_reader.hpp"

using namespace fdem;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_contact_piece_margins SCENE.yaml TIME [--set k=v ...]\n");
    return 2;
  }
  std::vector<std::string> overrides;
  for (int i = 3; i + 1 < argc; i += 2)
    if (std::string(argv[i]) == "--set") overrides.push_back(argv[i + 1]);
  const Scene scene = read_scene(argv[1], overrides);
  RunOptions options;
  options.quiet = true;
  options.write_output = false;
  auto sim = make_simulation(scene, options);
  const double until = std::stod(argv[2]);
  while (sim->time() + sim->time_step() < until) sim->step();
  const Model& model = sim->model();
  const double tolerance = scene.contact_sliver_tolerance;
  const double penalty = 1.0;
  std::size_t pairs = 0, kept = 0, main_pieces = 0;
  std::vector<double> actual, bounded;  // over the limit, of the kept pieces besides the main
  for (const CandidatePair& p : sim->contact_stage()->candidates()) {
    const TetCorners c = tet_corners(model, p.a), t = tet_corners(model, p.b);
    TetPairFrame frame;
    if (!prepare_tet_pair(c, t, frame)) continue;
    const unsigned left_out = negligible_parts(frame, tolerance);
    if (left_out == kEveryPiece) continue;
    const ContactPairResult all = potential_contact_without(c, t, penalty, left_out);
    if (!all.overlapping) continue;
    ++pairs;
    double mu[8], reach[8], bound[8];  // as negligible_parts has them
    const double thinnest = slab_depths(frame, mu);
    narrow_slab_depths(frame, mu, reach);
    const FrameMetrics metrics(frame);
    const PairForceBound pair = pair_force_bound(frame, metrics.pair(), reach, 1.0);
    const double limit =
        std::min(tolerance, kPressedFaceShare * thinnest) * pair.length * pair.length;
    piece_force_bounds(metrics.pair(), reach, pair, std::numeric_limits<double>::infinity(), bound);
    double contribution[8] = {};
    for (int k = 0; k < 8; ++k) {
      if ((left_out >> k) & 1u) continue;
      const ContactPairResult without =
          potential_contact_without(c, t, penalty, left_out | (1u << k));
      contribution[k] = largest_nodal_force_difference(all, without);
    }
    for (int side = 0; side < 2; ++side) {
      int largest = -1;
      for (int i = 0; i < 4; ++i) {
        const int k = 4 * side + i;
        if ((left_out >> k) & 1u || !(contribution[k] > 0.0)) continue;
        ++kept;
        if (largest < 0 || contribution[k] > contribution[largest]) largest = k;
      }
      main_pieces += largest >= 0;
      for (int i = 0; i < 4; ++i) {
        const int k = 4 * side + i;
        if (k == largest || (left_out >> k) & 1u || !(contribution[k] > 0.0)) continue;
        actual.push_back(contribution[k] / limit);
        bounded.push_back(std::isfinite(bound[k]) ? bound[k] / limit : 1e30);
      }
    }
  }
  std::printf(
      "%s at t = %.4g s: %zu pairs integrated, %.2f non-empty pieces kept per pair, "
      "%.2f main, %.2f others\n",
      argv[1], sim->time(), pairs, double(kept) / pairs, double(main_pieces) / pairs,
      double(actual.size()) / pairs);
  const double edges[] = {1e-3, 1e-2, 1e-1, 1, 10, 100, 1e3, 1e30};
  std::printf("other kept pieces, contribution / limit and bound / limit:\n");
  for (int e = 0; e < 8; ++e) {
    const double lo = e == 0 ? 0.0 : edges[e - 1];
    const auto count = [&](const std::vector<double>& v) {
      return std::count_if(v.begin(), v.end(), [&](double x) { return x >= lo && x < edges[e]; });
    };
    std::printf("  [%8.0e, %8.0e): %6ld  %6ld\n", lo, edges[e], count(actual), count(bounded));
  }
  return 0;
}
