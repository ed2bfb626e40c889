// The one-rank step domain: the step's collectives are the identity and nothing moves, so one
// rank runs Simulation::step's single path (drivers/step_domain.hpp).
#include <catch2/catch.hpp>
#include <stdexcept>

#include "core/error.hpp"
#include "drivers/step_domain.hpp"

using namespace fdem;

TEST_CASE("one-rank domain: sums, flags and gathers are the rank's own, checks throw as they are",
          "[step_domain]") {
  const std::unique_ptr<StepDomain> domain = one_rank_domain();
  CHECK_FALSE(domain->redistributes());
  std::vector<double> values = {1.5, -2.0, 0.0, 1e300};
  const std::vector<double> before = values;
  domain->sum(values);
  CHECK(values == before);
  CHECK(domain->any(true));
  CHECK_FALSE(domain->any(false));

  struct Record {
    std::int64_t id;
    double time;
    std::int32_t mode;
  };
  const std::vector<Record> mine = {{7, 0.25, 1}, {1LL << 40, 1e-9, 2}};
  const std::vector<Record> all = gather_records(*domain, mine);
  REQUIRE(all.size() == 2);
  CHECK(all[1].id == (1LL << 40));
  CHECK(all[1].time == 1e-9);
  CHECK(all[0].mode == 1);
  CHECK(gather_records(*domain, std::vector<Record>{}).empty());

  int runs = 0;
  domain->run_collectively([&] { ++runs; });
  CHECK(runs == 1);
  CHECK_THROWS_AS(domain->run_collectively([] { throw NumericalFailure("blow-up at step 3"); }),
                  NumericalFailure);
  CHECK_THROWS_WITH(domain->run_collectively([] { throw InputError("bad key"); }), "bad key");

  NodeArrays nodes;
  nodes.resize(2);
  nodes.x = {1, 2, 3, 4, 5, 6};
  domain->start_halo_exchange(nodes);
  domain->finish_halo_exchange(nodes);
  CHECK(nodes.x == std::vector<double>{1, 2, 3, 4, 5, 6});
}
