// The tet's internal force for four tets side by side (core/tet_force_kernel.hpp) against the
// one-tet instance of the same kernel: every lane's forces and energies to the last bit, with the
// lanes' laws, viscosities and inversions mixed.
#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "core/tet_force_kernel.hpp"
#include "core/tet_kernels.hpp"

using namespace fdem;

namespace {

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// A random tet of ~1 m, deformed by up to `strain` and moving at up to 1 m/s; `inverted` swaps
// two corners after the reference is taken.
struct RandomTet {
  double x[4][3], v[4][3], dm_inv[9], volume0;
};

RandomTet random_tet(std::mt19937_64& rng, double strain, bool inverted) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Vec3 X[4];
  TetReference ref;
  do {
    for (auto& p : X) p = Vec3(unit(rng), unit(rng), unit(rng));
    ref = tet_reference(X);
  } while (ref.volume < 0.02);
  RandomTet t;
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) {
      t.x[c][k] = X[c][k] + strain * unit(rng);
      t.v[c][k] = unit(rng);
    }
  if (inverted)
    for (int k = 0; k < 3; ++k) std::swap(t.x[1][k], t.x[2][k]);
  for (int e = 0; e < 9; ++e) t.dm_inv[e] = ref.dm_inv.data()[e];
  t.volume0 = ref.volume;
  return t;
}

template <template <class> class Law>
void check_lanes_against_one_tet(std::mt19937_64& rng, void (*lanes)(TetLaneBatch&)) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inverted_lanes = 0, viscous_lanes = 0;
  for (int round = 0; round < 2000; ++round) {
    RandomTet tet[lane_count];
    double lambda[lane_count], mu[lane_count], viscosity[lane_count];
    TetLaneBatch batch;
    for (int l = 0; l < lane_count; ++l) {
      const bool inverted = (round * lane_count + l) % 37 == 0;
      tet[l] = random_tet(rng, round % 2 ? 0.2 : 1e-4, inverted);
      inverted_lanes += inverted;
      lambda[l] = 1e9 * (1.0 + unit(rng));
      mu[l] = 1e9 * (1.0 + unit(rng));
      viscosity[l] = (round + l) % 3 == 0 ? 1e3 * unit(rng) : 0.0;
      viscous_lanes += viscosity[l] > 0.0;
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 3; ++k) {
          batch.x[c][k][l] = tet[l].x[c][k];
          batch.v[c][k][l] = tet[l].v[c][k];
        }
      for (int e = 0; e < 9; ++e) batch.dm_inv[e][l] = tet[l].dm_inv[e];
      batch.volume0[l] = tet[l].volume0;
      batch.viscosity[l] = viscosity[l];
      batch.lambda[l] = lambda[l];
      batch.mu[l] = mu[l];
    }
    // Batches with some viscous lanes run the viscous arithmetic for all four (undamped lanes
    // keep their elastic stress); the others skip it.
    batch.any_viscous = round % 3 != 1;
    if (!batch.any_viscous)
      for (double& eta : viscosity) eta = 0.0;
    for (int l = 0; l < lane_count; ++l) batch.viscosity[l] = viscosity[l];
    lanes(batch);
    for (int l = 0; l < lane_count; ++l) {
      TetCornerForces<double> one;
      tet_corner_forces(tet[l].x, tet[l].v, tet[l].dm_inv, tet[l].volume0,
                        Law<double>{lambda[l], mu[l]}, viscosity[l], viscosity[l] > 0.0, one);
      INFO("round " << round << ", lane " << l);
      REQUIRE(bits(batch.out.jacobian[l]) == bits(one.jacobian));
      REQUIRE(bits(batch.out.strain_energy[l]) == bits(one.strain_energy));
      REQUIRE(bits(batch.out.damping_power[l]) == bits(one.damping_power));
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 3; ++k)
          REQUIRE(bits(batch.out.force[c][k][l]) == bits(one.force[c][k]));
    }
  }
  CHECK(inverted_lanes > 100);
  CHECK(viscous_lanes > 1000);
}

}  // namespace

TEST_CASE("four neo-Hookean tets side by side give each the one-tet kernel's bits",
          "[tet][lanes]") {
  std::mt19937_64 rng(20261128);
  check_lanes_against_one_tet<NeoHookeanLaw>(rng, neo_hookean_tet_lanes);
}

TEST_CASE("four St. Venant-Kirchhoff tets side by side give each the one-tet kernel's bits",
          "[tet][lanes]") {
  std::mt19937_64 rng(11);
  check_lanes_against_one_tet<StVenantKirchhoffLaw>(rng, st_venant_kirchhoff_tet_lanes);
}

TEST_CASE("an inverted tet in a batch gets zero forces and energies, its lane mates their own",
          "[tet][lanes]") {
  std::mt19937_64 rng(3);
  TetLaneBatch batch;
  RandomTet tet[lane_count];
  for (int l = 0; l < lane_count; ++l) {
    tet[l] = random_tet(rng, 1e-3, l == 2);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) batch.x[c][k][l] = tet[l].x[c][k];
    for (int e = 0; e < 9; ++e) batch.dm_inv[e][l] = tet[l].dm_inv[e];
    batch.volume0[l] = tet[l].volume0;
    batch.viscosity[l] = 0.0;
    batch.lambda[l] = batch.mu[l] = 1e9;
  }
  neo_hookean_tet_lanes(batch);
  CHECK(batch.out.jacobian[2] < 0.0);
  CHECK(batch.out.strain_energy[2] == 0.0);
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) CHECK(batch.out.force[c][k][2] == 0.0);
  for (int l : {0, 1, 3}) {
    CHECK(batch.out.jacobian[l] > 0.0);
    CHECK(batch.out.strain_energy[l] > 0.0);
  }
}
