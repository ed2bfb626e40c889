// Scene keys `parallel:` and `output.format` / `output.mpi_io_hints`: read into the scene, with
// defaults, choices, --set overrides and errors naming the key and what is valid.
#include <catch2/catch.hpp>
#include <string>
#include <utility>
#include <vector>

#include "io/scene_reader.hpp"
#include "minimal_scene.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;
using namespace fdem::test_scenes;

TEST_CASE("the parallel block reads its two keys and rejects others", "[io]") {
  const fdem::Scene s =
      fdem::parse_scene(join_lines(minimal_lines()) +
                            "parallel: {rebalance_threshold: 1.25, redistribute_every: 40}\n",
                        "scene.yaml");
  CHECK(s.parallel.rebalance_threshold == 1.25);
  CHECK(s.parallel.redistribute_every == 40);
  const std::string typo =
      input_error(join_lines(minimal_lines()) + "parallel: {rebalance_treshold: 1.2}\n");
  CHECK_THAT(typo, Contains("parallel.rebalance_treshold") && Contains("rebalance_threshold"));
  const std::string negative =
      input_error(join_lines(minimal_lines()) + "parallel: {redistribute_every: -5}\n");
  CHECK_THAT(negative, Contains("parallel.redistribute_every") && Contains(">= 0"));
}

TEST_CASE("parallel.migration and parallel.repartition: defaults, choices, clear errors", "[io]") {
  const fdem::Scene defaults = fdem::parse_scene(minimal_plus(""), "scene.yaml");
  CHECK(defaults.parallel.migration == "incremental");
  CHECK(defaults.parallel.repartition == "measured");
  const fdem::Scene s = fdem::parse_scene(
      minimal_plus("parallel: {migration: full, repartition: threshold}\n"), "scene.yaml");
  CHECK(s.parallel.migration == "full");
  CHECK(s.parallel.repartition == "threshold");
  const std::string bad = input_error(minimal_plus("parallel: {migration: partial}\n"));
  CHECK_THAT(bad, Contains("parallel.migration") && Contains("incremental") && Contains("full"));
  const std::string worse = input_error(minimal_plus("parallel: {repartition: always}\n"));
  CHECK_THAT(worse, Contains("parallel.repartition") && Contains("measured"));
}

TEST_CASE("parallel.gid_offset: a 64-bit integer from 0 to below 2^62", "[io]") {
  CHECK(fdem::parse_scene(minimal_plus(""), "scene.yaml").parallel.gid_offset == 0);
  for (const std::string value : {"4294979641", "1099511627775", "4611686018427387903"})
    CHECK(fdem::parse_scene(minimal_plus("parallel: {gid_offset: " + value + "}\n"), "scene.yaml")
              .parallel.gid_offset == std::stoll(value));
  // From the command line too (the way the tests run a scene with large gids).
  CHECK(fdem::parse_scene(minimal_plus(""), "scene.yaml", {"parallel.gid_offset=4294979641"})
            .parallel.gid_offset == 4294979641LL);
  for (const std::string value : {"-1", "4611686018427387904", "9223372036854775807"}) {
    const std::string msg = input_error(minimal_plus("parallel: {gid_offset: " + value + "}\n"));
    CHECK_THAT(msg, Contains("parallel.gid_offset") && Contains(">= 0 and < 2^62"));
  }
  for (const std::string value : {"1.5", "1e12", "lots", "18446744073709551616"}) {
    const std::string msg = input_error(minimal_plus("parallel: {gid_offset: " + value + "}\n"));
    CHECK_THAT(msg, Contains("parallel.gid_offset") && Contains("expected an integer"));
  }
}

TEST_CASE("output.format and output.mpi_io_hints: xdmf frames with MPI-IO hints", "[io]") {
  const fdem::Scene d = fdem::parse_scene(join_lines(minimal_lines()), "scene.yaml");
  CHECK(d.output.format == fdem::OutputSpec::FrameFormat::vtu);  // today's frames by default
  CHECK(d.output.mpi_io_hints.empty());

  const fdem::Scene x =
      fdem::parse_scene(minimal_plus("output: {format: xdmf, mpi_io_hints: {striping_factor: 16, "
                                     "striping_unit: 4194304, romio_cb_write: enable}}\n"),
                        "scene.yaml");
  CHECK(x.output.format == fdem::OutputSpec::FrameFormat::xdmf);
  using Hints = std::vector<std::pair<std::string, std::string>>;
  CHECK(x.output.mpi_io_hints == Hints{{"striping_factor", "16"},
                                       {"striping_unit", "4194304"},
                                       {"romio_cb_write", "enable"}});

  const fdem::Scene v =
      fdem::parse_scene(join_lines(minimal_lines()), "scene.yaml", {"output.format=xdmf"});
  CHECK(v.output.format == fdem::OutputSpec::FrameFormat::xdmf);

  SECTION("a bad format names the key, the valid values and the nearest one") {
    const std::string msg = input_error(minimal_plus("output: {format: xdfm}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:18: output.format: 'xdfm' is not valid."));
    CHECK_THAT(msg, Contains("Did you mean 'xdmf'?"));
    CHECK_THAT(msg, Contains("Valid values: vtu, xdmf."));
    CHECK_THAT(
        input_error(join_lines(minimal_lines()), {"output.format=hdf5"}),
        StartsWith("scene.yaml: --set output.format=hdf5: output.format: 'hdf5' is not valid."));
  }
  SECTION("hints must be a mapping of names to single values") {
    CHECK_THAT(
        input_error(minimal_plus("output: {mpi_io_hints: [striping_factor]}\n")),
        StartsWith("scene.yaml:10:24: output.mpi_io_hints: expected a mapping of MPI-IO hint "
                   "names to values"));
    CHECK_THAT(input_error(minimal_plus("output: {mpi_io_hints: {striping_factor: [1, 2]}}\n")),
               StartsWith("scene.yaml:10:42: output.mpi_io_hints.striping_factor: expected one "
                          "value"));
    CHECK_THAT(input_error(minimal_plus("output: {mpi_io_hints: {cb-nodes: 4}}\n")),
               Contains("output.mpi_io_hints.cb-nodes: an MPI-IO hint name is letters, digits and "
                        "'_'"));
  }
}
