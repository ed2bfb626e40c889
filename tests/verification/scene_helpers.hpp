// Scene builders for the verification tests (the shared ones of drivers/scene_builders.hpp) and
// what a masonry test measures while a load is held.
#pragma once

#include <chrono>
#include <cmath>

#include "core/dynamics.hpp"
#include "drivers/scene_builders.hpp"

namespace fdem::testing {
using namespace fdem::builders;

// What a block did while a load was held: slid along x (m) and turned (rad) during the hold.
struct HoldResult {
  double slid = 0;
  double turned = 0;
  double wall = 0;  // s
  double balance = 0;
};

// Steps `sim` to its end; the hold starts at `hold_start`.  Piece 1 is the block.
inline HoldResult run_hold(Simulation& sim, double hold_start) {
  HoldResult r;
  const auto clock = std::chrono::steady_clock::now();
  Vec3 x0 = Vec3::Zero(), turn0 = Vec3::Zero();
  bool held = false;
  while (sim.time() < sim.scene().time.end - 1e-12) {
    sim.step();
    if (!held && sim.time() >= hold_start) {
      const PieceMotion m = piece_motions(sim.model())[1];
      x0 = m.centroid;
      turn0 = m.rotation;
      held = true;
    }
  }
  const PieceMotion m = piece_motions(sim.model())[1];
  r.slid = std::abs(m.centroid.x() - x0.x());
  r.turned = (m.rotation - turn0).norm();
  r.balance = sim.energy().balance_error();
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  return r;
}

}  // namespace fdem::testing
