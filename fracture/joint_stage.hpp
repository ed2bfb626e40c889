// Stages 2–3 of the step: forces of the cohesive joints (fracture/joint_kernels.hpp) added to the
// nodes in ascending joint gid, and the fracture bookkeeping — newly broken joints get their
// failure time and mode, and the caller hands their two tets over to contact.
//
// The cohesive history of every integration point lives here, sized to what is live: a pristine
// joint (no point past its peak or slipping, the common case in an intact body) keeps nothing
// but its slot index (4 bytes); the first update that damages or slips it gives it a full
// JointHistory (184 bytes) in a pool, whose energy terms start from the previous step's opening
// and shear, rebuilt from the previous positions x − Δt·v.  The model's JointArrays mirror what
// other parts read: broken flag, mode, failure time, damage.
#pragma once

#include <vector>

#include "core/model.hpp"
#include "fracture/intact_joint_kernel.hpp"
#include "fracture/joint_kernels.hpp"

namespace fdem {

struct JointStepSummary {
  double stored_energy = 0.0;        // J held by the intact joints at the current positions
  double fracture_dissipated = 0.0;  // J dissipated by bond degradation in this update
  double friction_dissipated = 0.0;  // J dissipated by Coulomb slip inside joints in this update
  LocalIndex newly_broken = 0;       // joints that broke in this update
  LocalIndex broken = 0;             // broken joints in total
};

// The joints' histories as the opaque records that travel with them (TravellingState), and back.
std::vector<std::uint8_t> joint_records(const std::vector<JointHistory>& history);
std::vector<JointHistory> joint_histories(const std::vector<std::uint8_t>& records);

class JointStage {
 public:
  // Builds one CohesiveLaw per model.joint_laws entry; throws InputError (naming the material or
  // interface) when a parameter set is invalid.
  explicit JointStage(const Model& model);

  static bool needed(const Model& model) { return model.joints.size() > 0; }

  // Advances every intact joint to the current positions, adds its forces to model.nodes.f in
  // ascending joint gid, and marks joints that break with `time` (s) and their failure mode.
  // With parallel roles, only joints with an active tet are computed, and only those whose tet A
  // is owned count in the energies and in JointStepSummary::newly_broken.
  // The dissipation terms cover the motion since the previous call, so for the trapezoid
  // accumulators of core/energy.hpp they are all "before" work (see docs/fracture-model.md).
  // `step` (s) is the time step that brought the nodes here (x = x_prev + step·v, with v the
  // nodes' velocities of the last half step): a joint leaving the pristine state takes its
  // previous opening and shear from x − step·v.
  JointStepSummary add_forces(Model& model, double time, double step);

  // Joints (indices) that broke in the last add_forces call: every one computed here (with parallel
  // roles the owners of both tets compute a joint, and each tells the ranks holding its tet).
  const std::vector<LocalIndex>& newly_broken() const { return newly_broken_; }

  // Stable step (s) of the joint springs alone.  Each intact point couples a_i and b_i with a
  // stiffness of at most max(k_n, k_t)·A0/3 (the frame terms vanish at zero gap when p_t = p_n);
  // Gershgorin on M⁻¹K bounds ω² by max over nodes of Σ 2·k·A0/3 / m.  Combine with the other
  // bounds by adding ω².
  double critical_time_step(const Model& model) const;

  // Parallel runs: the local joints changed (redistribution); take their histories (one per
  // local joint, in the model's joint order).
  void rebind(const Model& model, std::vector<JointHistory> history);
  // A joint that broke on another rank: mark the local copy broken at `time` with `mode`.
  void mark_broken(Model& model, LocalIndex joint, double time, std::uint8_t mode);

  const std::vector<CohesiveLaw>& laws() const { return laws_; }
  // Every local joint's history, in the model's joint order (pristine ones written out in full).
  std::vector<JointHistory> history() const;
  // Joint j's damage (mean D of its three points; 0 while pristine) and the time it broke (s; −1
  // while it holds).
  double damage(LocalIndex j) const {
    const std::int32_t slot = slot_[static_cast<std::size_t>(j)];
    return slot < 0 ? 0.0 : live_[static_cast<std::size_t>(slot)].damage();
  }
  double failure_time(LocalIndex j) const {
    const std::int32_t slot = slot_[static_cast<std::size_t>(j)];
    return slot < 0 ? -1.0 : live_[static_cast<std::size_t>(slot)].failure_time;
  }
  // Joints that hold a full history (the others are pristine).
  std::size_t live_histories() const { return live_.size(); }

 private:
  // Gives joint j a full history (zero; pristine joints keep no state); returns its slot in live_.
  std::int32_t promote(LocalIndex j);
  // Joint j's forces and energies from lane `lane` of a computed batch (its step not `leaves`).
  void add_intact(Model& model, LocalIndex j, const IntactJointBatch& batch, int lane, double share,
                  JointStepSummary& out);
  // Joint j through the full law on a full history (promoted first when pristine, its energy
  // terms from the positions x − step·v); marks it broken at `time` when it breaks.
  void add_full_law(Model& model, LocalIndex j, double share, double time, double step,
                    JointStepSummary& out);

  std::vector<CohesiveLaw> laws_;
  std::vector<IntactJointLaw> intact_laws_;  // what the pristine joints' step reads, per law
  std::vector<std::int32_t> slot_;           // per joint: index in live_, or −1 (pristine)
  std::vector<JointHistory> live_;           // histories of the joints that left the pristine state
  std::vector<LocalIndex> newly_broken_;
  LocalIndex broken_ = 0;
};

}  // namespace fdem
