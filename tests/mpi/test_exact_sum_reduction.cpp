// Exact sums added over the ranks (parallel/exact_sum_reduction) on 1–4 ranks: rank 0's sums are
// one process's sums of every value, bit for bit, whichever rank added which value; values of
// very different magnitudes, cancellations, a sum only one rank adds to, and an empty one.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/exact_sum.hpp"
#include "parallel/communicator.hpp"
#include "parallel/exact_sum_reduction.hpp"

using namespace fdem;

namespace {

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Value i of sum s: magnitudes from 1e-300 to 1e300, signs mixed.
double value(int s, int i) {
  const double magnitude = std::pow(10.0, (37 * i + 11 * s) % 600 - 300);
  return (i % 3 == 0 ? -1.0 : 1.0) * magnitude * (1.0 + 1e-3 * i);
}

}  // namespace

TEST_CASE("exact sums added over the ranks equal one process's, bit for bit", "[exact_sum]") {
  const Communicator comm = Communicator::world();
  constexpr int sums = 5, values = 400;
  std::vector<ExactSum> mine(sums), all(sums);
  for (int s = 0; s < sums; ++s)
    for (int i = 0; i < values; ++i) {
      if (s == 3 && i > 0) break;  // sum 3: one value, at the rank that has i = 0
      if (s == 4) break;           // sum 4: empty
      const double v = value(s, i);
      all[s].add(v);
      // Dealt to ranks by a hash of the index, so every rank adds to every sum but sum 3.
      if (static_cast<int>((i * 2654435761u) % static_cast<unsigned>(comm.size())) == comm.rank())
        mine[s].add(v);
    }
  // Cancellation: +x on one rank, −x on another gives zero exactly.
  mine[2].add(comm.rank() == 0 ? 1e20 : 0.0);
  mine[2].add(comm.rank() == comm.size() - 1 ? -1e20 : 0.0);
  reduce_exact_sums_to_root(mine, comm);
  if (comm.rank() == 0)
    for (int s = 0; s < sums; ++s) {
      INFO("sum " << s << " on " << comm.size() << " ranks");
      CHECK(same_bits(mine[s].value(), all[s].value()));
    }
  // Called again (the next row): the same answer, no message left over from the first call.
  std::vector<ExactSum> again(1);
  again[0].add(comm.rank() + 0.5);
  reduce_exact_sums_to_root(again, comm);
  if (comm.rank() == 0) CHECK(again[0].value() == 0.5 * comm.size() * comm.size());
}
