// The potential-contact kernel against the previous implementation kept as the benchmarks'
// baseline: two evaluations of the same formulas that must agree to round-off on every kind of
// pair a run meets (deep, shallow, face on face, touching, apart).
#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "contact/potential_contact_kernels.hpp"
#include "test_potential_contact_support.hpp"

using namespace fdem;
using namespace fdem::test_contact;

namespace {

struct Agreement {
  int pairs = 0, overlapping = 0;
  double worst_force = 0.0;   // max |Δf| / max |f| over the pairs
  double worst_energy = 0.0;  // |ΔU| / U
  double worst_weight = 0.0;  // max |Δ centroid weight|
};

void compare(const TetCorners& c, const TetCorners& t, double penalty, Agreement& a) {
  const ContactPairResult now = potential_contact(c, t, penalty);
  const ContactPairResult before = potential_contact_baseline(c, t, penalty);
  ++a.pairs;
  REQUIRE(now.overlapping == before.overlapping);
  if (!now.overlapping) return;
  ++a.overlapping;
  const double scale = std::max(largest_nodal_force(before), 1e-300);
  for (int v = 0; v < 4; ++v) {
    a.worst_force = std::max(a.worst_force,
                             (now.force_contactor[v] - before.force_contactor[v]).norm() / scale);
    a.worst_force =
        std::max(a.worst_force, (now.force_target[v] - before.force_target[v]).norm() / scale);
    a.worst_weight = std::max(a.worst_weight, std::abs(now.centroid_weights_contactor[v] -
                                                       before.centroid_weights_contactor[v]));
    a.worst_weight = std::max(a.worst_weight, std::abs(now.centroid_weights_target[v] -
                                                       before.centroid_weights_target[v]));
  }
  a.worst_energy = std::max(a.worst_energy, std::abs(now.energy - before.energy) / before.energy);
  CHECK(std::abs(now.overlap_volume - before.overlap_volume) <= 1e-12 * before.overlap_volume);
}

}  // namespace

TEST_CASE("the kernel agrees with the baseline implementation to round-off",
          "[potential_contact]") {
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double penalty = 1.0e10;

  SECTION("random overlapping pairs, deep and shallow") {
    Agreement a;
    for (int k = 0; k < 400; ++k) {
      TetCorners c, t;
      random_overlapping_pair(rng, Vec3(3.0, -2.0, 1.0), c, t, penalty);
      compare(c, t, penalty, a);
      // Pulled back along the centre line to a shallow overlap (or just apart).
      const Vec3 dir = tet_centroid(c) - tet_centroid(t);
      for (double s : {0.2, 0.5, 1.0}) {
        TetCorners moved = c;
        for (int v = 0; v < 4; ++v) moved.x[v] += s * dir;
        compare(moved, t, penalty, a);
        compare(t, moved, penalty, a);
      }
    }
    INFO("forces " << a.worst_force << ", energy " << a.worst_energy << ", weights "
                   << a.worst_weight);
    CHECK(a.overlapping > 800);
    CHECK(a.worst_force < 1e-13);   // measured 7.9e-16
    CHECK(a.worst_energy < 1e-13);  // 5.1e-16
    CHECK(a.worst_weight < 1e-13);  // 3.3e-16
  }

  SECTION("face on face, pressed 1e-2 to 1e-8 of the size, and exactly touching") {
    // (1,512 of the 3,000 overlap: a random shift can take the faces apart; touching gives none.)
    Agreement a;
    for (double depth : {1e-2, 1e-4, 1e-6, 1e-8, 0.0}) {
      for (int k = 0; k < 300; ++k) {
        TetCorners lower, upper;
        face_on_face(rng, depth, lower, upper);
        compare(lower, upper, penalty, a);
        compare(upper, lower, penalty, a);
      }
    }
    INFO("forces " << a.worst_force << ", energy " << a.worst_energy);
    CHECK(a.overlapping > 1200);
    CHECK(a.worst_force < 1e-13);   // measured 5.3e-16
    CHECK(a.worst_energy < 1e-13);  // 5.3e-16
  }

  SECTION("pairs apart or rejected give zero in both") {
    Agreement a;
    for (int k = 0; k < 200; ++k) {
      const TetCorners t = random_tet(rng, 1.0, Vec3::Zero());
      const TetCorners c = random_tet(rng, 1.0, 1.2 * random_unit(rng));
      compare(c, t, penalty, a);
    }
    CHECK(a.pairs == 200);
  }
}
