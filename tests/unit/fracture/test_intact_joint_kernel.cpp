// The batched intact step (fracture/intact_joint_kernel.hpp) against the one-joint reference
// (joint_frame + joint_intact_step): same forces, energy and state to the last bit, and the same
// verdict (degenerate, leaves, done) for every lane.
#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "fracture/intact_joint_kernel.hpp"
#include "fracture_test_support.hpp"

using namespace fdem;
using fdem::test::rock_parameters;

namespace {

// One joint: a random triangle a0 a1 a2 (≈ 0.1 m) and b_i = a_i + gap_i with gaps of `scale`
// (m), in random directions; `kind` 1 makes the mid-surface flat (all six nodes on a line).
void random_joint(std::mt19937_64& rng, double scale, int kind, double (&x)[18]) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int c = 0; c < 9; ++c) x[c] = 0.1 * unit(rng) + (c % 3 == 0 ? 3.0 : 0.0);
  if (kind == 1)
    for (int i = 1; i < 3; ++i)
      for (int k = 0; k < 3; ++k) x[3 * i + k] = x[k] + 0.5 * i * (x[3 + k] - x[k]);
  for (int c = 0; c < 9; ++c) x[9 + c] = x[c] + (kind == 1 ? 0.0 : scale * unit(rng));
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

TEST_CASE(
    "the batched intact step gives the one-joint reference's forces, energy and state bit "
    "for bit",
    "[fracture][joint]") {
  CohesiveParameters soft = rock_parameters();
  soft.tangential_penalty = 1.0e11;  // k_t ≠ k_n: the frame terms do not vanish
  const CohesiveLaw laws[2] = {CohesiveLaw(rock_parameters()), CohesiveLaw(soft)};
  const IntactJointLaw intact_laws[2] = {IntactJointLaw(laws[0]), IntactJointLaw(laws[1])};
  std::mt19937_64 rng(20261128);
  // Gaps from far below the peak opening (1.67 µm) to beyond it: every verdict occurs.
  const double scales[] = {1e-9, 1e-7, 5e-7, 1e-6, 3e-6};
  int verdicts[3] = {0, 0, 0};
  for (int round = 0; round < 4000; ++round) {
    IntactJointBatch batch;
    double x[intact_lanes][18];  // the lanes' six nodes, one after the other: node 6l + i
    int law_of[intact_lanes];
    LocalIndex ids[intact_lanes][6];
    const LocalIndex* id[intact_lanes];
    double w[intact_lanes];
    const IntactJointLaw* law[intact_lanes];
    for (int l = 0; l < intact_lanes; ++l) {
      const int kind = (round * intact_lanes + l) % 97 == 0 ? 1 : 0;
      random_joint(rng, scales[(round + l) % 5], kind, x[l]);
      law_of[l] = (round + 3 * l) % 2;
      for (int i = 0; i < 6; ++i) ids[l][i] = 6 * l + i;
      id[l] = ids[l];
      w[l] = 0.004 + 0.001 * l;
      law[l] = &intact_laws[law_of[l]];
    }
    set_lanes(batch, &x[0][0], id, w, law);
    IntactJointBatch baseline = batch;
    intact_joint_steps(baseline);            // as compiled here (x86-64 baseline)
    intact_joint_steps_for_this_cpu(batch);  // AVX2 where the CPU has it, as in the joint stage
    for (int l = 0; l < intact_lanes; ++l) REQUIRE(batch.step[l] == baseline.step[l]);
    for (int c = 0; c < 18; ++c)
      for (int l = 0; l < intact_lanes; ++l)
        if (batch.step[l] != IntactStep::leaves)
          REQUIRE(bits(batch.force[c][l]) == bits(baseline.force[c][l]));
    for (int l = 0; l < intact_lanes; ++l) {
      Vec3 xv[6];
      for (int i = 0; i < 6; ++i) xv[i] = Vec3(x[l][3 * i], x[l][3 * i + 1], x[l][3 * i + 2]);
      JointForce reference;
      for (auto& f : reference.force) f.setZero();
      IntactJointState state;
      JointFrame frame;
      IntactStep expected = IntactStep::done;
      if (!joint_frame(xv, frame))
        expected = IntactStep::degenerate;
      else if (!joint_intact_step(xv, frame, 0.004 + 0.001 * l, laws[law_of[l]], state, reference))
        expected = IntactStep::leaves;
      REQUIRE(batch.step[l] == expected);
      ++verdicts[static_cast<int>(expected)];
      if (expected == IntactStep::leaves) continue;
      for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 3; ++k)
          REQUIRE(bits(batch.force[3 * i + k][l]) == bits(reference.force[i][k]));
      REQUIRE(bits(batch.stored_energy[l]) == bits(reference.stored_energy));
      if (expected == IntactStep::degenerate) continue;
      // The joint stage keeps no state for pristine joints and rebuilds it when one leaves that
      // state: the rebuilt state must be the one the step leaves.
      IntactJointState rebuilt;
      REQUIRE(intact_state_at(xv, laws[law_of[l]], rebuilt));
      for (int i = 0; i < 3; ++i) {
        REQUIRE(bits(rebuilt.previous_opening[i]) == bits(state.previous_opening[i]));
        REQUIRE(bits(rebuilt.previous_shear_sq[i]) == bits(state.previous_shear_sq[i]));
      }
    }
  }
  CHECK(verdicts[0] > 1000);  // done
  CHECK(verdicts[1] > 10);    // degenerate
  CHECK(verdicts[2] > 1000);  // leaves
}
