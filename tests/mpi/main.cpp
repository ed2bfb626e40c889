// Runner of the MPI tests: initialises MPI, runs Catch2 on every rank, and returns the same exit
// code on every rank (non-zero if any rank had a failing test).  Run with mpiexec
// (tests/CMakeLists).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "parallel/communicator.hpp"

int main(int argc, char** argv) {
  fdem::MpiEnvironment environment(&argc, &argv);
  const fdem::Communicator world = fdem::Communicator::world();
  const int failed = Catch::Session().run(argc, argv);
  return world.max(failed);
}
