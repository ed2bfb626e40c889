// Simulation::step — the physics order of one time step — and the stages it calls.  One rank
// and N ranks take the same path; the StepDomain (drivers/step_domain.hpp) is what differs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "contact/contact_stage.hpp"
#include "contact/detection.hpp"
#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/initial_stress.hpp"
#include "core/time_step.hpp"
#include "drivers/histories.hpp"
#include "drivers/interrupt.hpp"
#include "drivers/loads.hpp"
#include "drivers/run_limits.hpp"
#include "drivers/simulation.hpp"
#include "drivers/step_domain.hpp"
#include "drivers/step_record.hpp"
#include "fracture/joint_stage.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

namespace {

// Steps between two checks of the deformed mesh's stable step against the time step (the
// minimum-step guard, LS-DYNA's DTMIN idea): every 100 steps while the bound is at least 0.8 of
// the step (check_deformed_step then mostly needs only a cheap lower bound), every 10 steps below
// 0.8, every step below 0.6, so that a crushing element is caught before it inverts.
constexpr double stability_check_relaxed_ratio = 0.8;
long steps_to_next_stability_check(double bound_over_step) {
  return bound_over_step < 0.6 ? 1 : bound_over_step < stability_check_relaxed_ratio ? 10 : 100;
}
// The guard fires when the deformed mesh's stable-step bound is below this fraction of the time
// step.  The bound is conservative (the auto step sits at 0.7–0.9 of the limit found by
// bisection, docs/architecture.md), so at half the step the true limit is surely passed: no run
// that would stay stable is stopped.
constexpr double stable_step_margin = 0.5;

// A run whose energy balance error exceeds this has blown up (well-resolved runs stay below 1 %).
constexpr double runaway_balance_error = 0.2;
// Stored energy above this multiple of the energy put in means a mode is growing (see check_state).
constexpr double runaway_energy_growth = 100.0;

}  // namespace

// ---------------------------------------------------------------------------------------------
// One time step: the whole physics order in one place.
// ---------------------------------------------------------------------------------------------
void Simulation::step() {
  StepRecord r;
  share_broken_joints();                // 3b last step's broken joints: to the ranks holding them
  const bool detect = detection_due();  // 4a a node went buffer/2, or a body cracked
  if (migration_due(detect))            // 4b before a detection cycle: re-balance, migrate,
    redistribute(detect);               //    rebuild the halo
  apply_loads();                        // 0  gravity (tilt, ramp) and base velocities at t_n
  add_internal_forces(r);               // 1  m·g + F = Ds·Dm⁻¹, stress: tet gid order
  add_joint_forces(r);                  // 2  cohesive joints in joint gid order; 3 they break
  if (detect) detect_contacts();        // 4  NBS: the pairs within the buffer
  add_contact_forces(r);                // 5  potential tet–tet contact with Coulomb friction
  add_external_forces(r);               // 6  absorbing dashpots, surface loads at t_n
  record_histories();                   // 6b histories.csv at t_n: reactions, positions x_n
  integrate(r);                         // 7  central difference with prescribed velocities
  start_halo_exchange();                // 8  ghost positions travel while step n+1 begins
  check_deformed_step(r);               //    minimum-step guard on x_n+1
  sum_over_ranks(r);                    //    the step's one blocking reduction
  book_energy(r);                       //    energy balance at t_n
  check_step(r);                        //    blow-up, tunnelling, crushed elements
  time_ += dt_;
  ++steps_;
}

// Joints break where they are computed (the owners of both tets compute each); the ranks that
// hold a copy of either tet learn of it at the start of the next step from the tet's owner, so
// that every copy of the joint and of its tets' contact state changes at the same step, on any
// number of ranks, and no other rank takes part (a neighbour-only exchange; the count that says
// whether any joint broke travels in the step's reduction).  The freed tets become contact
// partners by a detection at the positions of the last one, on the ranks that hold them only.
// The first break in a body is told to every rank: the body's enclosed tets, anywhere, enter the
// contact detection that follows (once per body).  A restart rebuilds the same state from the
// joints' broken flags.
void Simulation::share_broken_joints() {
  if (!breaks_pending_) return;
  breaks_pending_ = false;
  Timed timed(clocks_[fracture]);
  std::vector<GlobalId> about;
  std::vector<BrokenJoint> notices;
  for (const BrokenJoint& b : own_breaks_)
    for (const GlobalId tet : {b.tet_a, b.tet_b}) {
      const LocalIndex t = model_.tets.find(tet);
      if (t >= 0 && model_.tets.is_owned(t)) {
        about.push_back(tet);
        notices.push_back(b);
      }
    }
  std::vector<BrokenJoint> known = records_to_holders(*domain_, about, notices);
  known.insert(known.end(), own_breaks_.begin(), own_breaks_.end());
  if (bodies_cracking_) {  // every rank, together: which bodies cracked
    bodies_cracking_ = false;
    std::vector<std::int32_t> cracked;
    if (contact_)
      for (const BrokenJoint& b : own_breaks_)
        for (const std::int32_t body : {b.body_a, b.body_b})
          if (!contact_->body_cracked(body)) cracked.push_back(body);
    for (const std::int32_t body : gather_records(*domain_, cracked)) contact_->crack_body(body);
  }
  own_breaks_.clear();
  std::vector<std::pair<LocalIndex, LocalIndex>> freed;
  for (const BrokenJoint& b : known) {
    const auto it = std::lower_bound(model_.joints.gid.begin(), model_.joints.gid.end(), b.joint);
    if (it != model_.joints.gid.end() && *it == b.joint)
      joints_->mark_broken(model_, static_cast<LocalIndex>(it - model_.joints.gid.begin()), b.time,
                           static_cast<std::uint8_t>(b.mode));
    freed.emplace_back(model_.tets.find(b.tet_a), model_.tets.find(b.tet_b));
  }
  if (contact_) contact_->release_bonds(model_, freed);
}

bool Simulation::detection_due() {
  if (!plan_.contact) return false;
  Timed timed(clocks_[detection]);
  // From the last step's reduction, the same on every rank; before the first step and after a
  // restart, from one reduction of its own.
  if (detection_due_ < 0) detection_due_ = domain_->any(contact_->detection_due(model_)) ? 1 : 0;
  return detection_due_ > 0 || !contact_->detected();
}

bool Simulation::migration_due(bool detecting) const {
  if (!domain_->redistributes()) return false;
  const long every = scene_.parallel.redistribute_every;
  return (detecting && moved_since_halo_) || (every > 0 && steps_ > 0 && steps_ % every == 0);
}

void Simulation::apply_loads() {
  if (!loads_->active()) return;
  Timed timed(clocks_[external]);
  loads_->apply(time_, dt_, model_);
}

void Simulation::add_internal_forces(StepRecord& r) {
  const double halo_before = clocks_[halo].seconds;
  {
    Timed timed(clocks_[internal]);
    // Split phase: interior tets while the ghost positions of step 8 arrive (bit-identical sums).
    r.forces = compute_internal_forces(
        model_, split_, [&] { finish_halo_exchange(); },
        plan_.gravity ? &model_.gravity : nullptr);  // + m·g (6)
  }
  clocks_[internal].seconds -= clocks_[halo].seconds - halo_before;  // waiting is halo time
  if (plan_.initial_stress) {  // after every tet's own force: tets in gid order again
    Timed timed(clocks_[internal]);
    r.forces.strain_energy += add_initial_stress_forces(initial_stress_, model_).energy;
  }
}

void Simulation::add_joint_forces(StepRecord& r) {
  if (!plan_.joints) return;
  Timed timed(clocks_[joints]);
  r.joints = joints_->add_forces(model_, time_, dt_);
  // 3 fracture: the joints that broke here, shared at the start of the next step.
  for (LocalIndex b : joints_->newly_broken()) {
    const LocalIndex a = model_.joints.tets[2 * b], c = model_.joints.tets[2 * b + 1];
    own_breaks_.push_back({model_.joints.gid[b], model_.tets.gid[a], model_.tets.gid[c],
                           joints_->failure_time(b), model_.joints.mode[b],
                           model_.pieces.body_of(model_.tets.piece[a]),
                           model_.pieces.body_of(model_.tets.piece[c])});
    if (contact_ && (!contact_->body_cracked(own_breaks_.back().body_a) ||
                     !contact_->body_cracked(own_breaks_.back().body_b)))
      r.flags.bodies_cracked = 1.0;
  }
  r.flags.broken_joints = static_cast<double>(r.joints.newly_broken);
}

void Simulation::detect_contacts() {
  Timed timed(clocks_[detection]);
  contact_->detect(model_);
}

void Simulation::add_contact_forces(StepRecord& r) {
  if (!plan_.contact) return;
  Timed timed(clocks_[contact]);
  r.contact = contact_->add_forces(model_, dt_);
}

void Simulation::add_external_forces(StepRecord& r) {
  if (!absorbing_ && !plan_.surface_loads) return;
  Timed timed(clocks_[external]);
  // Gravity's m·g is already in: the internal forces start from it (1).
  if (absorbing_) r.boundary_before = absorbing_->add_forces(dt_, model_);
  if (plan_.surface_loads) {  // pressure and traction on boundary faces, at t_n
    loads_->add_surface_forces(time_, model_);
    r.surface_power_before = loads_->surface_power(model_);
    if (scene_.quasi_static.active_at(time_))  // for the unbalanced-force ratio
      r.surface_force = loads_->surface_force_magnitude();
  }
}

void Simulation::record_histories() {
  if (!histories_ || !histories_->due(time_, dt_)) return;
  Timed timed(clocks_[output]);
  histories_->sample(model_, time_, dt_);
}

void Simulation::integrate(StepRecord& r) {
  NodeArrays& nodes = model_.nodes;
  Timed timed(clocks_[integration]);
  // The stored velocity is v(t − dt/2): at the start turn the initial v(0) into it (half kick).
  if (steps_ == 0) start_half_step(nodes);
  StepDamping damping;
  if (const QuasiStaticSpec& q = scene_.quasi_static; q.active_at(time_))
    damping = {true, q.local_damping, q.kinetic() && stop_motion_};
  r.motion = integrate_central_difference(dt_, nodes, damping);
  kinetic_damping_stops_ += damping.stop_motion ? 1 : 0;
  if (absorbing_) r.boundary_after = absorbing_->dissipation_after(dt_, model_);
  moved_since_halo_ = true;
  // The surface loads' work goes with the reactions' (external_work), by the same trapezoid.
  if (plan_.surface_loads) {
    r.motion.constraint_work_before += 0.5 * dt_ * r.surface_power_before;
    r.motion.constraint_work_after += 0.5 * dt_ * loads_->surface_power(model_);
  }
  r.flags.nonfinite_velocity = r.motion.finite ? 0.0 : 1.0;
  if (!plan_.contact) return;
  r.contact_after = contact_->work_after(model_, dt_);  // friction and dashpots with v_n+½
  // How far the nodes went: whether the next step must detect, and whether a node crossed more
  // than the thinnest element in this step (tunnelling).
  r.flags.detection_due =
      contact_->detection_due_after_step(model_, r.motion.max_displacement_increment,
                                         r.motion.largest_coordinate)
          ? 1.0
          : 0.0;
  r.flags.tunnelling = r.motion.max_displacement_increment > tunnel_size_ ? 1.0 : 0.0;
}

void Simulation::start_halo_exchange() {
  if (!domain_->redistributes()) return;  // one rank: no ghosts
  Timed timed(clocks_[halo]);
  domain_->start_halo_exchange(model_.nodes);
}

void Simulation::finish_halo_exchange() {
  if (!domain_->redistributes()) return;
  Timed timed(clocks_[halo]);
  domain_->finish_halo_exchange(model_.nodes);
}

// Minimum-step guard: has an element been deformed so far that the time step is above its
// stable step?  (Checked on x_{n+1}, reported by check_step.)
void Simulation::check_deformed_step(StepRecord& r) {
  if (steps_ < next_stability_check_) return;
  // Where the step is set by something stiffer than the tets (joints, contact penalties) a cheap
  // lower bound clears the top threshold, and the exact bound would give the same schedule and no
  // flag: its eigenvalue problems (~4 µs per tet) are skipped.
  const double lower_bound = fdem::critical_time_step_lower_bound(model_);
  if (lower_bound >= stability_check_relaxed_ratio * dt_)
    r.deformed = CriticalStep{lower_bound, -1};
  else
    r.deformed = fdem::critical_time_step(model_);
  next_stability_check_ = steps_ + steps_to_next_stability_check(r.deformed.dt / dt_);
  r.flags.step_too_large =
      r.deformed.limiting_tet >= 0 && r.deformed.dt < stable_step_margin * dt_ ? 1.0 : 0.0;
}

// Every rank's energy terms (each counts what it owns) and flags, in one reduction; then the
// decisions for the next step, identical on every rank.
void Simulation::sum_over_ranks(StepRecord& r) {
  r.flags.inverted_tet = r.forces.min_jacobian > 0.0 ? 0.0 : 1.0;
  r.flags.interrupted = interrupt_signal() != 0 ? 1.0 : 0.0;
  const auto start = std::chrono::steady_clock::now();
  const auto values = summed_values(r);
  reduced_.resize(values.size());  // kept: no allocation per step
  for (std::size_t i = 0; i < values.size(); ++i) reduced_[i] = *values[i];
  domain_->sum(reduced_);
  for (std::size_t i = 0; i < values.size(); ++i) *values[i] = reduced_[i];
  reduction_seconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.motion.finite = r.flags.nonfinite_velocity == 0.0;
  detection_due_ = r.flags.detection_due > 0.0 ? 1 : 0;
  // Kinetic damping: from the summed energy, so the same on every rank.
  stop_motion_ =
      scene_.quasi_static.kinetic() &&
      kinetic_energy_peaked(kinetic_half_step_, r.motion.kinetic_energy_half_step, stop_motion_);
  breaks_pending_ = r.flags.broken_joints > 0.0;
  bodies_cracking_ = r.flags.bodies_cracked > 0.0;
  // A signal on any rank ends the run after this step on every rank.
  if (r.flags.interrupted > 0.0) interrupt_ = interrupt_signal() != 0 ? interrupt_signal() : -1;
  // Quasi-static runs: the mean unbalanced force over the applied ones (weight, supports and
  // surface loads), the equilibrium test of quasi_static.equilibrium_ratio (FLAC's and 3DEC's
  // "ratio", averaged).
  const double applied =
      r.motion.mass * model_.gravity.norm() + r.motion.support_force + r.surface_force;
  force_ratio_ = r.motion.mass > 0.0 && applied > 0.0 ? r.motion.unbalanced_force / applied
                                                      : std::numeric_limits<double>::quiet_NaN();
}

// The energy balance at t_n from the reduced terms.
void Simulation::book_energy(const StepRecord& r) {
  EnergyTerms energy;
  energy.strain = r.forces.strain_energy;
  if (plan_.joints) {
    energy.joint = r.joints.stored_energy;
    // The joints' dissipation covers x_{n-1} -> x_n, so all of it is "before" work at t_n.
    energy.dissipated_fracture = ledger_.fracture.add(r.joints.fracture_dissipated, 0.0);
    energy.dissipated_friction = joint_friction_.add(r.joints.friction_dissipated, 0.0);
  }
  if (plan_.contact) {
    // What friction took from the bodies (trapezoid work, as the integrator sees it) is stored in
    // the stick springs or dissipated: slip, and springs released when a contact ends.
    energy.contact = r.contact.energy + r.contact.friction_spring_energy;
    energy.dissipated_friction +=
        ledger_.friction.add(r.contact.work_before.friction, r.contact_after.friction) -
        r.contact.friction_spring_energy;
  }
  energy.kinetic = r.motion.kinetic_energy;
  kinetic_half_step_ = r.motion.kinetic_energy_half_step;
  // Gravity potential = − its trapezoid work, ½dt·g·(Σm·v⁻ + Σm·v⁺) per step: exact for a constant
  // g (−Σ m g·(x − x0)) and right when g changes in time (tilting tables).
  if (plan_.gravity)
    energy.gravity = -ledger_.gravity.add(0.5 * dt_ * model_.gravity.dot(r.motion.momentum_before),
                                          0.5 * dt_ * model_.gravity.dot(r.motion.momentum_after));
  const double viscous_step = r.forces.damping_power * dt_;  // element damping, J
  // Element and contact dashpots, and the quasi-static damping, local and kinetic (its work ≤ 0).
  energy.dissipated_damping = ledger_.damping.add(
      0.5 * viscous_step + r.contact.work_before.damping - r.motion.damping_work_before,
      0.5 * viscous_step + r.contact_after.damping - r.motion.damping_work_after);
  energy.external_work =
      ledger_.external.add(r.motion.constraint_work_before, r.motion.constraint_work_after);
  if (absorbing_)
    energy.dissipated_boundary = ledger_.boundary.add(r.boundary_before, r.boundary_after);
  ledger_.record(energy);
  // Work through t_n+½ counts too: the plain kinetic energy already holds the half step after t_n.
  energy_input_ =
      std::max({energy_input_, std::abs(ledger_.initial_total()), std::abs(energy.external_work),
                std::abs(ledger_.external.through_previous), std::abs(energy.gravity),
                std::abs(ledger_.gravity.through_previous), energy_floor_});
}

// An inverted or NaN tet is seen by the ranks that hold it: when any rank has one (counted in the
// reduction), the check runs collectively and every rank stops with that rank's message.  The
// other checks use reduced values, so every rank decides alike without a collective.
void Simulation::check_step(const StepRecord& r) {
  const auto state = [&] { check_state(r.forces, r.motion.finite); };
  if (r.flags.inverted_tet > 0.0)
    domain_->run_collectively(state);
  else
    state();
  // Tunnelling first: a body that jumped an element in one step also deforms the tets that hold
  // ghost copies of its nodes (not yet exchanged), which the minimum-step guard would report.
  if (r.flags.tunnelling > 0.0) domain_->run_collectively([&] { check_tunnelling(r.motion); });
  if (r.flags.step_too_large > 0.0)
    domain_->run_collectively([&] { check_stable_step(r.deformed); });
  // Bodies placed into each other: the penalty pushes them apart at once and their contact energy
  // becomes motion.  Touching bodies have none at t = 0 (round-off: below 1e-12 of Σ E·V).
  if (time_ == 0.0 && r.contact.energy > 1e3 * energy_floor_ && is_root())
    std::fprintf(stderr,
                 "fdem: warning: bodies overlap at t = 0: their contact energy is %.3g J (%.2g of "
                 "the tets' sum of E x V): the penalty pushes them apart at once and that energy "
                 "becomes motion; place the bodies apart or exactly touching\n",
                 r.contact.energy, 1e-12 * r.contact.energy / energy_floor_);
}

// The stage state that moves with the local entries when the model is (re)distributed.
TravellingState Simulation::travelling_state() const {
  TravellingState state;
  if (contact_) {
    state.x_at_detection = contact_->positions_at_detection(model_);
    state.tet_joint_state = contact_->tet_joint_states();
    state.pairs = friction_records(contact_->friction_entries());
  } else {
    state.x_at_detection = model_.nodes.x;
  }
  if (joints_) {
    state.joint_record_bytes = sizeof(JointHistory);
    state.joint_records = joint_records(joints_->history());
  }
  return state;
}

void Simulation::rebind_stages(TravellingState& state, bool detected, bool candidates_travelled) {
  if (contact_)
    contact_->rebind(model_, std::move(state.x_at_detection), std::move(state.tet_joint_state),
                     friction_entries(state.pairs), detected,
                     candidates_travelled ? &state.candidates : nullptr);
  if (joints_) joints_->rebind(model_, joint_histories(state.joint_records));
  loads_->rebind(model_);
  if (absorbing_) absorbing_->rebind(model_);
  if (plan_.initial_stress)
    initial_stress_ = initial_stresses(scene_.initial_stress, scene_.gravity, model_);
  build_internal_force_split(model_, split_);
}

// `detecting`: a detection at the current positions follows at once (the halo is built for it).
// Else the candidate pairs of the last detection travel with their tets
// (parallel.redistribute_every between detections): the last detection is never repeated.
void Simulation::redistribute(bool detecting) {
  finish_halo_exchange();
  Timed timed(clocks_[migration]);
  TravellingState state = travelling_state();
  const bool keep_candidates = contact_ && contact_->detected() && !detecting;
  if (keep_candidates) state.candidates = contact_->candidate_gids(model_);
  std::vector<double> contact_cost;  // per local tet, in units of one tet's internal force
  if (contact_) {
    // Relative costs from bench_contact_pair and bench_internal_forces (docs/benchmarks.md): a
    // tet's internal force ~36 ns, a separated candidate pair rejected in ~85 ns (≈ 3 tets), an
    // overlapping pair 1.5–2.6 µs (≈ 60 tets).
    constexpr double candidate_cost = 3.0, overlap_cost = 60.0;
    contact_cost.assign(static_cast<std::size_t>(model_.tets.size()), 0.0);
    const std::vector<CandidatePair>& pairs = contact_->candidates();
    const std::vector<std::uint8_t>& overlapping = contact_->overlapping();
    for (std::size_t i = 0; i < pairs.size(); ++i)
      contact_cost[pairs[i].a] +=
          candidate_cost + (i < overlapping.size() && overlapping[i] ? overlap_cost : 0.0);
    contact_->release_until_rebind();  // `state` holds what rebind needs
  }
  // This rank's compute seconds since the last cycle: what a re-partition could even out.
  double busy = 0.0;
  for (const Stage s : {internal, joints, fracture, detection, contact, external, integration})
    busy += clocks_[s].seconds;
  domain_->redistribute(model_, state, contact_cost, busy - busy_at_last_cycle_);
  busy_at_last_cycle_ = busy;
  rebind_stages(state, keep_candidates, keep_candidates);
  moved_since_halo_ = false;
}

void Simulation::start_half_step(NodeArrays& nodes) const {
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    for (int k = 0; k < 3; ++k)
      if (!(nodes.constrained[n] & (1u << k)))
        nodes.v[3 * n + k] -= 0.5 * dt_ * nodes.f[3 * n + k] / nodes.mass[n];
}

// What to try after a numerical failure, from the time step against the critical step.
std::string Simulation::step_advice() const {
  std::ostringstream advice;
  const double ratio = dt_ / dt_critical_;
  advice << " The time step is " << dt_ << " s = " << ratio << " x the critical step "
         << dt_critical_ << " s";
  if (!scene_.time.auto_step && ratio > 1.0)
    advice << ": it is above the stability limit; use time.step: auto or a step below "
           << dt_critical_ << " s.";
  else
    advice << ". Try a smaller time.safety (e.g. " << std::min(0.5, 0.5 * scene_.time.safety)
           << "), check for very distorted elements, or slow down prescribed velocities.";
  if (contact_ && uses_corner_contact(scene_))
    advice << " Under corner contact ("
           << (scene_.contact_formulation == ContactFormulation::automatic
                   ? "contact.formulation: auto, as in every run quasi-static throughout without "
                     "joints"
                   : "contact.formulation: corners")
           << ") a block's corner caught beside another block's edge (blocks tumbling across "
              "each other) can put energy in: such runs need contact.formulation: potential "
              "(docs/verification.md, \"Corner contact\").";
  return advice.str();
}

void Simulation::check_state(const InternalForceSummary& forces, bool velocities_finite) const {
  const std::string advice = step_advice();
  if (!(forces.min_jacobian > 0.0)) {
    const LocalIndex t = forces.min_jacobian_tet;
    const std::int32_t piece = model_.tets.piece[t];
    std::ostringstream msg;
    msg << "numerical failure at step " << steps_ << " (t = " << time_ << " s): tetrahedron "
        << model_.tets.gid[t] << " of body '" << model_.body_names[model_.pieces.body_of(piece)]
        << "' (piece " << model_.pieces.index_in_body(piece) << ") "
        << (std::isnan(forces.min_jacobian) ? "has NaN coordinates" : "inverted")
        << " (det F = " << forces.min_jacobian << ")." << advice;
    throw NumericalFailure(msg.str());
  }
  if (!velocities_finite) {
    std::ostringstream msg;
    msg << "numerical failure at step " << steps_ << " (t = " << time_
        << " s): velocities became NaN or infinite." << advice;
    throw NumericalFailure(msg.str());
  }
  // Central difference conserves ½m·v⁻·v⁺ + U even past the stability limit (the kinetic term
  // turns negative as a mode grows), so the balance cannot reveal an instability.  The stored
  // energy with the plain ½m|v|² can: in a stable run it stays within a few times the energy put
  // in (initial, external work, gravity; ≤ 1/(1 − (ωΔt/2)²) ≈ 10× at 0.95 of the limit), while a
  // mode past the limit grows without bound.
  const EnergyTerms& e = ledger_.current();
  const double stored = kinetic_half_step_ + e.strain + e.contact + e.joint;
  if (steps_ > 10 && stored > runaway_energy_growth * energy_input_) {
    std::ostringstream msg;
    msg << "numerical failure at step " << steps_ << " (t = " << time_
        << " s): the run is unstable — the stored energy " << stored << " J grew to "
        << stored / energy_input_ << " x the energy put in (" << energy_input_
        << " J): a mode beyond the stability limit is growing." << advice;
    throw NumericalFailure(msg.str());
  }
  if (steps_ > 10 && ledger_.balance_error() > runaway_balance_error &&
      std::abs(e.total() - ledger_.initial_total()) > energy_floor_) {
    std::ostringstream msg;
    msg << "numerical failure at step " << steps_ << " (t = " << time_
        << " s): the run is unstable — the energy "
        << "balance error reached " << ledger_.balance_error() * 100 << " % (total energy "
        << ledger_.current().total() << " J, initially " << ledger_.initial_total() << " J)."
        << advice;
    throw NumericalFailure(msg.str());
  }
}

// Throws NumericalFailure when `deformed` (the stable step of the current shapes) fell below the
// time step: the run is past its stability limit and would blow up within some steps.
void Simulation::check_stable_step(const CriticalStep& deformed) const {
  if (deformed.limiting_tet < 0 || !(deformed.dt < stable_step_margin * dt_)) return;
  std::ostringstream msg;
  msg << "numerical failure at step " << steps_ << " (t = " << time_
      << " s): the run is unstable — the stable time step of the "
      << (steps_ > 0 ? "deformed " : "") << "mesh is " << deformed.dt
      << " s, below half the time step (minimum-step guard), set by "
      << describe_tet(model_, deformed.limiting_tet) << "." << step_advice();
  throw NumericalFailure(msg.str());
}

// Throws NumericalFailure when a node of this rank went further in one step than the thinnest
// element is thick: contact only sees positions at whole steps, so it could have passed through an
// element unseen (tunnelling), and a penetration that deep pushes the wrong way anyway.
void Simulation::check_tunnelling(const IntegrationSummary& motion) const {
  const double travel = motion.max_displacement_increment;
  if (!(travel > tunnel_size_) || motion.fastest_node < 0) return;
  const NodeArrays& nodes = model_.nodes;
  const LocalIndex n = motion.fastest_node;
  const std::int32_t piece = nodes.piece[n];
  const double speed = travel / dt_;
  std::ostringstream msg;
  msg << "numerical failure at step " << steps_ << " (t = " << time_ << " s): node " << nodes.gid[n]
      << " of body '" << model_.body_names[model_.pieces.body_of(piece)] << "' (piece "
      << model_.pieces.index_in_body(piece) << ") moved " << travel << " m in one step (speed "
      << speed << " m/s), more than the smallest element size " << tunnel_size_
      << " m: contact only sees the positions at whole steps, so the body would pass through "
         "elements without touching them (tunnelling). Use a smaller time step (below "
      << tunnel_size_ / speed
      << " s: time.step, or a smaller time.safety) or check the initial and prescribed "
         "velocities; a larger contact buffer (contact.buffer, now "
      << contact_->buffer()
      << " m) makes detection less frequent but cannot catch a crossing within one step.";
  throw NumericalFailure(msg.str());
}

}  // namespace fdem
