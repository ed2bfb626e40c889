#include "drivers/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "contact/contact_stage.hpp"
#include "contact/detection.hpp"
#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/initial_stress.hpp"
#include "core/model_builder.hpp"
#include "core/state_hash.hpp"
#include "core/tet_kernels.hpp"
#include "core/time_step.hpp"
#include "drivers/histories.hpp"
#include "drivers/interrupt.hpp"
#include "drivers/loads.hpp"
#include "drivers/mesh_files.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/output_times.hpp"
#include "drivers/process_memory.hpp"
#include "drivers/progress.hpp"
#include "drivers/restart_check.hpp"
#include "drivers/run_files.hpp"
#include "drivers/run_limits.hpp"
#include "fracture/joint_kernels.hpp"
#include "fracture/joint_stage.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"
#include "parallel/file_mesh_chunks.hpp"
#include "parallel/piece_directory.hpp"

namespace fdem {

namespace {

class Timed {
 public:
  explicit Timed(StageClock& clock) : clock_(clock), start_(std::chrono::steady_clock::now()) {}
  ~Timed() {
    clock_.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    ++clock_.calls;
  }

 private:
  StageClock& clock_;
  std::chrono::steady_clock::time_point start_;
};

// Steps between two checks of the deformed mesh's stable step against the time step (the
// minimum-step guard, LS-DYNA's DTMIN idea): a pass over the tets like one internal-force pass,
// so about 1 % of the run time; every 10 steps once the bound is below 0.8 of the step, every
// step below 0.6, so that a crushing element is caught before it inverts.
long steps_to_next_stability_check(double bound_over_step) {
  return bound_over_step < 0.6 ? 1 : bound_over_step < 0.8 ? 10 : 100;
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

// The distribution's settings from the scene's `parallel` block.
DistributionSettings distribution_settings(const ParallelSpec& spec) {
  DistributionSettings settings;
  settings.rebalance_threshold = spec.rebalance_threshold;
  settings.partitioner = spec.partitioner == "rcb"    ? GeometricMethod::rcb
                         : spec.partitioner == "hsfc" ? GeometricMethod::hsfc
                                                      : GeometricMethod::rib;
  settings.random_parts = spec.partitioner == "random";
  return settings;
}

}  // namespace

std::vector<std::string> StagePlan::describe() const {
  std::vector<std::string> s;
  s.push_back("internal forces (tetrahedra)");
  s.push_back(joints ? "joint forces + fracture" : "joint forces: skipped (no joints)");
  s.push_back(contact ? "contact detection + contact forces"
                      : "contact: skipped (no contact partners)");
  s.push_back(std::string("external forces: ") + (gravity ? "gravity" : "none") +
              (kinematic_loads ? " + prescribed velocities" : "") +
              (surface_loads ? " + surface loads" : "") +
              (absorbing ? " + absorbing boundaries (dashpots)" : ""));
  if (initial_stress) s.push_back("initial stress of the tets (added to the internal forces)");
  s.push_back("integrate (central difference)");
  return s;
}

Simulation::Simulation(Scene scene, Model model, RunOptions options, const Communicator* comm)
    : Simulation(std::move(scene), std::move(model), std::move(options), comm, nullptr, -1.0, {}) {}

Simulation::Simulation(Scene scene, Model model, RunOptions options, const Communicator* comm,
                       std::unique_ptr<Distribution> distribution, double contact_buffer,
                       std::vector<std::uint8_t> tet_joint_state)
    : scene_(std::move(scene)),
      model_(std::move(model)),
      options_(std::move(options)),
      comm_(comm) {
  const char* names[n_stages] = {
      "internal_forces", "joint_forces", "fracture",    "contact_detection", "contact_forces",
      "external_forces", "integrate",    "halo_update", "redistribution",    "output"};
  for (int s = 0; s < n_stages; ++s) clocks_[s].name = names[s];
  // Distributed start: the model is this rank's part with its halo, and what concerns the whole
  // model comes from reductions over the owned entries; otherwise it is the whole model.
  const bool distributed = distribution != nullptr;
  const auto global_min = [&](double v) { return distributed ? comm_->min(v) : v; };
  const auto global_sum = [&](auto v) { return distributed ? comm_->sum(v) : v; };
  loads_ = std::make_unique<LoadSchedule>(scene_, model_);
  plan_.gravity = scene_.gravity.squaredNorm() > 0.0 || loads_->changes_gravity();
  plan_.kinematic_loads =
      std::any_of(scene_.loads.begin(), scene_.loads.end(), [](const LoadSpec& l) {
        return l.kind == LoadSpec::Kind::velocity || l.kind == LoadSpec::Kind::base_motion;
      });
  plan_.surface_loads = loads_->has_surface_loads();
  // A surface load that acts on no face is a mistake in the scene (a region beside the model).
  for (const auto& [index, owned] : loads_->surface_face_counts())
    if (global_sum(owned) == 0) {
      const LoadSpec& load = scene_.loads[static_cast<std::size_t>(index)];
      throw InputError((load.where.empty()
                            ? scene_.source_path + ": loads[" + std::to_string(index) + "]"
                            : load.where) +
                       ": surface load '" + load.name + "' acts on no face: no boundary face " +
                       (load.region ? "has its three corners in the region's box at t = 0"
                                    : "belongs to its bodies") +
                       " (faces shared by two tets or by a joint are not boundary faces)");
    }

  plan_.contact = ContactStage::needed(model_);
  const CriticalStep critical = fdem::critical_time_step(model_);
  dt_critical_ = global_min(critical.dt);
  // Energies below this are round-off for the model (1e-12 of Σ E·V, J): a balance "error" among
  // them says nothing about stability.
  for (LocalIndex t = 0; t < model_.tets.size(); ++t)
    if (model_.tets.is_owned(t))
      energy_floor_ += 1e-12 * model_.materials[model_.tets.material[t]].young *
                       std::abs(model_.tets.volume0[t]);
  energy_floor_ = global_sum(energy_floor_);
  if (plan_.contact) {
    contact_ = std::make_unique<ContactStage>(
        model_, ContactSettings{distributed ? contact_buffer : scene_.contact_buffer,
                                scene_.contact_skip_enclosed});
    // Elastic and contact stiffness add, so do their ω² = (2/Δt)².
    const double dt_contact = global_min(contact_->critical_time_step(model_));
    // Tunnelling guard (check_tunnelling): the thinnest element a node could cross unseen.
    double thinnest = std::numeric_limits<double>::infinity();
    for (LocalIndex t = 0; t < model_.tets.size(); ++t) {
      if (!model_.tets.is_owned(t)) continue;
      Vec3 x[4];
      for (int c = 0; c < 4; ++c)
        x[c] = vec3_at(model_.nodes.x.data(), model_.tets.nodes[4 * t + c]);
      thinnest = std::min(thinnest, smallest_altitude(x));
    }
    tunnel_size_ = global_min(thinnest);
    dt_critical_ =
        1.0 / std::sqrt(1.0 / (dt_critical_ * dt_critical_) + 1.0 / (dt_contact * dt_contact));
  }
  // On N ranks from the distributed start a rank may hold no joint while others do: every rank
  // runs the joint stages when the model has joints.
  plan_.joints =
      distributed ? comm_->max(std::int64_t{model_.joints.size()}) > 0 : JointStage::needed(model_);
  if (plan_.joints) {
    joints_ = std::make_unique<JointStage>(model_);
    // Joint springs add ω² too.  Each owned node's joints are all held with it, in gid order.
    const double dt_joint = global_min(joints_->critical_time_step(model_));
    dt_critical_ =
        1.0 / std::sqrt(1.0 / (dt_critical_ * dt_critical_) + 1.0 / (dt_joint * dt_joint));
    if (contact_) {  // tets bonded by an intact joint never pair in contact
      std::vector<std::pair<LocalIndex, LocalIndex>> bonds;
      for (LocalIndex j = 0; j < model_.joints.size(); ++j)
        if (!model_.joints.broken[j])
          bonds.emplace_back(model_.joints.tets[2 * j], model_.joints.tets[2 * j + 1]);
      contact_->set_bonds(model_.tets.size(), bonds);
      contact_->enclose(model_.tets.enclosed);
    }
    model_.tets.enclosed = {};  // start-up only: the contact stage's joint state carries it
  }
  if (!scene_.initial_stress.empty()) {
    plan_.initial_stress = true;
    initial_stress_ = initial_stresses(scene_.initial_stress, scene_.gravity, model_);
    check_initial_equilibrium(distributed);
  }
  if (!scene_.absorbing.empty()) {
    plan_.absorbing = true;
    absorbing_ = std::make_unique<AbsorbingBoundary>(scene_.absorbing, model_);
    check_absorbing_faces(distributed);
    // Dashpots c at a node of mass m damp its highest mode by ξ = c/(2mω), ω = 2/Δt: the step
    // shrinks by √(1+ξ²) − ξ as for viscous damping (explicit in v_{n−½}).
    const double rate =
        distributed ? comm_->max(absorbing_->max_rate(model_)) : absorbing_->max_rate(model_);
    const double xi = 0.25 * rate * dt_critical_;
    dt_critical_ *= std::sqrt(1.0 + xi * xi) - xi;
  }
  dt_ = scene_.time.auto_step ? scene_.time.safety * dt_critical_ : scene_.time.step;
  if (!std::isfinite(dt_) || dt_ <= 0.0)
    throw InputError(scene_.source_path + ": could not determine a time step (critical step " +
                     std::to_string(dt_critical_) + " s)");
  std::int64_t owned_tets = 0;
  for (LocalIndex t = 0; t < model_.tets.size(); ++t) owned_tets += model_.tets.is_owned(t);
  whole_nodes_ = global_sum(std::int64_t{model_.nodes.n_owned});
  whole_tets_ = global_sum(owned_tets);
  std::int64_t owned_joints = 0;  // by their tet A
  for (LocalIndex j = 0; j < model_.joints.size(); ++j)
    owned_joints += model_.tets.is_owned(model_.joints.tets[2 * j]);
  whole_joints_ = global_sum(owned_joints);
  reference_hash_ = distributed ? global_reference_hash(model_, *comm_)
                                : reference_hash(model_.nodes, model_.gid_offset);
  next_checkpoint_time_ = scene_.output.checkpoint_every;
  if (distributed) {  // the stages were made on the local model: bind them to its halo
    distributed_start_ = true;
    distribution_ = std::move(distribution);
    TravellingState state = travelling_state();
    // A tet bonded by a joint that is not held here (its partner lies outside the halo) is
    // still bonded: its joint state came from the owners.
    if (contact_ && joints_) {
      FDEM_VERIFY(tet_joint_state.size() == static_cast<std::size_t>(model_.tets.size()),
                  "a joint state per local tet");
      state.tet_joint_state = std::move(tet_joint_state);
    }
    rebind_stages(state, false);
  }
  // Monitors are found by tet gid (rank-independent), so before the restart and the whole-model
  // start's distribution.
  if (scene_.output.histories.enabled && options_.write_output)
    histories_ = std::make_unique<HistoryRecorder>(scene_, model_, comm_);
  // A restart overwrites the state of the model (and of the stages) with the checkpoint's.
  if (!options_.restart_path.empty()) {
    mark_phase(CommPhase::restart);
    restore_checkpoint(options_.restart_path);
    moved_since_distribution_ = true;  // the halo was made for the start positions
    mark_phase(CommPhase::startup);
  }
  // Every rank decides alike; collectively, so that all leave with the message and exit code 2.
  if (comm_ && comm_->size() > 1)
    comm_->run_collectively([&] { check_run_limits(); });
  else
    check_run_limits();
  // N ranks, whole-model start: everything above came from the whole model (the same on every
  // rank); now keep this rank's part and halo.
  if (!distributed && comm_ && comm_->size() > 1) {
    const DistributionSettings settings = distribution_settings(scene_.parallel);
    // Blocks that touch at the start should share a rank: the first detection, on the whole
    // model, gives the partitioner those pairs (one rank detects at the same positions in step 0).
    std::vector<std::pair<LocalIndex, LocalIndex>> touching;
    if (contact_) {
      if (!contact_->detected()) contact_->detect(model_);
      for (const CandidatePair& p : contact_->candidates()) touching.emplace_back(p.a, p.b);
    }
    const TravellingState whole = travelling_state();
    TravellingState local_state;
    Model local;
    distribution_ = std::make_unique<Distribution>(*comm_, settings, model_, whole,
                                                   contact_ ? contact_->buffer() : 0.0, touching,
                                                   local, local_state);
    model_ = std::move(local);
    rebind_stages(local_state, contact_ && contact_->detected());
  }
  // Start-up is over: note its peak, give freed buffers back, and count the step loop afresh.
  startup_peak_rss_kib_ = peak_rss_kib();
  release_free_memory();
  reset_peak_rss();
}

// Refuses a run that cannot advance (a restart past time.end) or needs more steps than the
// scene's limits allow; decided from the whole model, so every rank throws alike.
void Simulation::check_run_limits() const {
  if (!options_.restart_path.empty() && !(scene_.time.end > time_)) {
    std::ostringstream msg;
    msg << scene_.source_path << ": time.end = " << scene_.time.end
        << " s is not after the time of the checkpoint '" << options_.restart_path << "' (" << time_
        << " s, step " << steps_
        << "): there is nothing to continue. Set a later time.end (--set time.end=...).";
    throw InputError(msg.str());
  }
  check_step_limit(scene_, time_, dt_, [this] { return step_origin(); });
}

// Where the time step comes from, for messages: the element that sets the elastic critical step
// and the contact and joint stiffness bounds.
std::string Simulation::step_origin() const {
  std::ostringstream out;
  out.precision(3);
  if (scene_.time.auto_step)
    out << "The step is time.safety " << scene_.time.safety << " x the critical step "
        << dt_critical_ << " s, set by:";
  else
    out << "The step is time.step (the critical step is " << dt_critical_ << " s:";
  const CriticalStep elastic = fdem::critical_time_step(model_);
  out << " elastic " << elastic.dt << " s at " << describe_tet(model_, elastic.limiting_tet);
  if (contact_) {
    out << ", contact " << contact_->critical_time_step(model_) << " s (contact penalties";
    for (std::size_t m = 0; m < model_.materials.size(); ++m)
      out << " " << model_.materials[m].name << " " << contact_->material_penalty()[m] << " Pa";
    out << ")";
  }
  if (joints_) out << ", cohesive joints " << joints_->critical_time_step(model_) << " s";
  out << (scene_.time.auto_step ? "." : ").");
  return out.str();
}

bool Simulation::is_root() const {
  return !comm_ || comm_->rank() == 0;
}

void Simulation::rebind_stages(TravellingState& state, bool detected) {
  if (contact_)
    contact_->rebind(model_, std::move(state.x_at_detection), std::move(state.tet_joint_state),
                     state.friction, detected);
  if (joints_) joints_->rebind(model_, std::move(state.joint_history));
  loads_->rebind(model_);
  if (absorbing_) absorbing_->rebind(model_);
  if (plan_.initial_stress)
    initial_stress_ = initial_stresses(scene_.initial_stress, scene_.gravity, model_);
  build_internal_force_split(model_, split_);
}

// The stage state that moves with the local entries when the model is (re)distributed.
TravellingState Simulation::travelling_state() const {
  TravellingState state;
  if (contact_) {
    state.x_at_detection = contact_->x_at_detection();
    state.tet_joint_state = contact_->tet_joint_states();
    state.friction = contact_->friction_entries();
  } else {
    state.x_at_detection = model_.nodes.x;
  }
  if (joints_) state.joint_history = joints_->history();
  return state;
}

void Simulation::redistribute(bool detecting) {
  TravellingState state = travelling_state();
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
    contact_->release_until_rebind();  // `state` holds what rebind needs; pairs are re-detected
  }
  mark_phase(CommPhase::redistribution);
  distribution_->redistribute(model_, state, contact_cost);
  rebind_stages(state, contact_ && contact_->detected() && !detecting);
  redistribute_pending_ = false;
  moved_since_distribution_ = false;
  mark_phase(CommPhase::step);
}

// Joints break where they are computed; the owner of tet A tells every rank, so that every copy
// of the joint and every copy of its tets' contact state changes at the same step as on one rank.
bool Simulation::share_broken_joints(bool detection_due) {
  struct Broken {
    GlobalId joint, tet_a, tet_b;
    double time;
    std::int32_t mode, body_a, body_b;
  };
  std::vector<Broken> mine;
  for (LocalIndex b : joints_->newly_broken()) {
    const LocalIndex a = model_.joints.tets[2 * b], c = model_.joints.tets[2 * b + 1];
    mine.push_back({model_.joints.gid[b], model_.tets.gid[a], model_.tets.gid[c],
                    model_.joints.failure_time[b], model_.joints.mode[b],
                    model_.pieces.body_of(model_.tets.piece[a]),
                    model_.pieces.body_of(model_.tets.piece[c])});
  }
  // One reduction: joints broken anywhere, and ranks whose nodes call for contact detection.
  std::vector<std::int64_t>& counts = reduced_counts_;  // kept: no allocation per step
  counts.assign({static_cast<std::int64_t>(mine.size()), detection_due});
  comm_->sum_in_place(counts);
  if (counts[0] == 0) return counts[1] > 0;
  const std::vector<Broken> all = comm_->allgatherv(mine);
  const auto local_tet = [&](GlobalId gid) -> LocalIndex {  // local tets are in ascending gid
    const auto it = std::lower_bound(model_.tets.gid.begin(), model_.tets.gid.end(), gid);
    return it != model_.tets.gid.end() && *it == gid
               ? static_cast<LocalIndex>(it - model_.tets.gid.begin())
               : -1;
  };
  for (const Broken& b : all) {
    const auto it = std::lower_bound(model_.joints.gid.begin(), model_.joints.gid.end(), b.joint);
    if (it != model_.joints.gid.end() && *it == b.joint)
      joints_->mark_broken(model_, static_cast<LocalIndex>(it - model_.joints.gid.begin()), b.time,
                           static_cast<std::uint8_t>(b.mode));
    if (contact_) {
      contact_->release_bond(local_tet(b.tet_a), local_tet(b.tet_b));
      contact_->crack_body(b.body_a);
      contact_->crack_body(b.body_b);
    }
  }
  return true;  // released bonds: every rank re-detects, as one rank does
}

Simulation::~Simulation() = default;

// ---------------------------------------------------------------------------------------------
// One time step: the whole physics order in one place.
// ---------------------------------------------------------------------------------------------
void Simulation::step() {
  NodeArrays& nodes = model_.nodes;
  EnergyTerms energy;

  // Completes the ghost exchange posted at the end of the previous step (stage 8).
  const auto complete_halo = [&] {
    if (!halo_in_flight_) return;
    Timed timed(clocks_[halo]);
    distribution_->finish_halo_exchange(nodes);
    halo_in_flight_ = false;
  };
  // N ranks: does this step detect because a node went more than buffer/2?  Decided from the
  // last step's reduction (identical on every rank).  The halo is then rebuilt at these positions
  // before detecting, so that the detection sees every partner however far a node went in the
  // last step (the halo margin assumes buffer/2 of travel from where it was built).
  bool travel_detection = false;
  if (distribution_ && plan_.contact) {
    Timed timed(clocks_[detection]);
    travel_detection =
        detection_due_ >= 0
            ? detection_due_ > 0 || !contact_->detected()
            : comm_->max(static_cast<std::int32_t>(contact_->detection_due(model_))) > 0;
  }
  if (distribution_) {
    // 4b redistribution: before a detection cycle (or after one that a broken joint started):
    // re-balance, migrate, rebuild the halo
    const long every = scene_.parallel.redistribute_every;
    const bool before_detection = travel_detection && moved_since_distribution_;
    if (redistribute_pending_ || before_detection ||
        (every > 0 && steps_ > 0 && steps_ % every == 0)) {
      complete_halo();
      Timed timed(clocks_[migration]);
      redistribute(travel_detection);
    }
  }

  // 0 time-dependent loads: gravity (tilt, ramp) at t_n, base velocities for the coming half step
  if (loads_->active()) {
    Timed timed(clocks_[external]);
    loads_->apply(time_, dt_, model_);
  }

  // 1 internal forces: F = Ds·Dm⁻¹, stress, nodal forces added in ascending tet gid
  InternalForceSummary forces;
  if (distribution_) {
    // Split phase: interior tets while the ghost positions of step 8 arrive (bit-identical sums).
    const double halo_before = clocks_[halo].seconds;
    {
      Timed timed(clocks_[internal]);
      forces = compute_internal_forces(model_, split_, complete_halo);
    }
    clocks_[internal].seconds -= clocks_[halo].seconds - halo_before;  // waiting is halo time
  } else {
    Timed timed(clocks_[internal]);
    forces = compute_internal_forces(model_);
  }
  if (plan_.initial_stress) {  // after every tet's own force: tets in gid order again
    Timed timed(clocks_[internal]);
    forces.strain_energy += add_initial_stress_forces(initial_stress_, model_).energy;
  }

  // 2 joint forces: cohesive joints in ascending joint gid
  JointStepSummary j;
  bool detection_due = false;  // N ranks: whether any rank needs contact detection this step
  if (plan_.joints) {
    {
      Timed timed(clocks_[joints]);
      j = joints_->add_forces(model_, time_);
    }
    // 3 fracture: the tets of newly broken joints become contact partners
    Timed timed(clocks_[fracture]);
    if (distribution_)
      detection_due = share_broken_joints(travel_detection);
    else if (j.newly_broken > 0 && contact_)
      for (LocalIndex b : joints_->newly_broken()) {
        const LocalIndex tet_a = model_.joints.tets[2 * b], tet_b = model_.joints.tets[2 * b + 1];
        contact_->release_bond(tet_a, tet_b);
        for (LocalIndex t : {tet_a, tet_b})
          contact_->crack_body(model_.pieces.body_of(model_.tets.piece[t]));
      }
  }

  // 4 contact detection: only when a node has moved more than buffer/2 since the last one
  if (plan_.contact) {
    Timed timed(clocks_[detection]);
    if (distribution_) {
      if (!plan_.joints) detection_due = travel_detection;  // with joints: stage 3's answer
      if (detection_due) {
        contact_->detect(model_);
        // A detection that a broken joint started mid-step redistributes at the next step.
        if (!travel_detection) redistribute_pending_ = true;
      }
    } else {
      contact_->detect_if_needed(model_);
    }
  }

  // 5 contact forces: potential tet–tet contact over the candidate pairs
  ContactForceSummary c;
  if (plan_.contact) {
    Timed timed(clocks_[contact]);
    c = contact_->add_forces(model_, dt_);
  }

  // 6 external forces
  if (plan_.gravity) {
    Timed timed(clocks_[external]);
    add_gravity(model_.gravity, nodes);
  }
  double boundary_before = 0.0, boundary_after = 0.0;  // J, dashpot dissipation (owned nodes)
  if (absorbing_) {
    Timed timed(clocks_[external]);
    boundary_before = absorbing_->add_forces(dt_, model_);
  }

  // 6 surface loads: pressure and traction on boundary faces, at t_n
  double surface_power_before = 0.0;  // W, with v(t_n − dt/2)
  if (plan_.surface_loads) {
    Timed timed(clocks_[external]);
    loads_->add_surface_forces(time_, model_);
    surface_power_before = loads_->surface_power(model_);
  }

  // 6b histories.csv row at t_n: reactions (f complete), positions x_n, before they move
  if (histories_ && histories_->due(time_, dt_)) {
    Timed timed(clocks_[output]);
    histories_->sample(model_, time_, dt_);
  }

  // 7 integrate: central difference with prescribed velocities
  IntegrationSummary motion;
  {
    Timed timed(clocks_[integrate]);
    // The stored velocity is v(t − dt/2): at the start turn the initial v(0) into it (half kick).
    if (steps_ == 0) start_half_step(nodes);
    const double local_damping =
        scene_.quasi_static.active_at(time_) ? scene_.quasi_static.local_damping : 0.0;
    motion = integrate_central_difference(dt_, nodes, local_damping);
    if (absorbing_) boundary_after = absorbing_->dissipation_after(dt_, model_);
    moved_since_distribution_ = true;
    // The surface loads' work goes with the reactions' (external_work), by the same trapezoid.
    if (plan_.surface_loads) {
      motion.constraint_work_before += 0.5 * dt_ * surface_power_before;
      motion.constraint_work_after += 0.5 * dt_ * loads_->surface_power(model_);
    }
  }
  ContactWork contact_after;  // the "after" halves of friction and dashpot work (v_n+½ known now)
  if (plan_.contact) contact_after = contact_->work_after(model_, dt_);
  // How far the nodes went: whether the next step must detect, and whether a node crossed more
  // than the thinnest element in this step (tunnelling); both decided in the reduction below.
  NodeTravel travel;
  if (plan_.contact)
    travel = node_travel(nodes.x.data(), contact_->x_at_detection().data(), nodes.v.data(), dt_,
                         nodes.n_owned);
  const bool detect_next =
      plan_.contact && detection_needed(travel.since_detection, contact_->buffer());
  double tunnel_ranks = plan_.contact && travel.step > tunnel_size_ ? 1.0 : 0.0;

  // 8 halo update: post the ghost exchange now, complete it at the start of the next step
  if (distribution_) {
    Timed timed(clocks_[halo]);
    distribution_->start_halo_exchange(nodes);
    halo_in_flight_ = true;
  }

  // Minimum-step guard: has an element been deformed so far that the time step is above its
  // stable step?  (Checked on x_{n+1}; reported below with the other checks.)
  CriticalStep deformed;
  if (steps_ >= next_stability_check_) {
    deformed = fdem::critical_time_step(model_);
    next_stability_check_ = steps_ + steps_to_next_stability_check(deformed.dt / dt_);
  }
  const bool step_too_large = deformed.limiting_tet >= 0 && deformed.dt < stable_step_margin * dt_;

  double bad_tet_ranks = 0.0;  // N ranks: ranks holding an inverted or NaN tet
  double crushed_ranks = step_too_large ? 1.0 : 0.0;
  // The energy terms of every rank (each counts what it owns) in one reduction.
  if (distribution_) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<double>& terms = reduced_terms_;  // kept: no allocation per step
    terms.assign({forces.strain_energy,
                  forces.damping_power,
                  j.stored_energy,
                  j.fracture_dissipated,
                  j.friction_dissipated,
                  c.work_before.damping,
                  c.energy,
                  c.friction_spring_energy,
                  c.work_before.friction,
                  contact_after.friction,
                  motion.kinetic_energy,
                  motion.kinetic_energy_half_step,
                  motion.constraint_work_before,
                  motion.constraint_work_after,
                  motion.momentum_before.x(),
                  motion.momentum_before.y(),
                  motion.momentum_before.z(),
                  motion.momentum_after.x(),
                  motion.momentum_after.y(),
                  motion.momentum_after.z(),
                  motion.finite ? 0.0 : 1.0,
                  forces.min_jacobian > 0.0 ? 0.0 : 1.0,
                  interrupt_signal() != 0 ? 1.0 : 0.0,
                  crushed_ranks,
                  detect_next ? 1.0 : 0.0,
                  tunnel_ranks,
                  contact_after.damping,
                  boundary_before,
                  boundary_after,
                  motion.local_damping_work_before,
                  motion.local_damping_work_after});
    comm_->sum_in_place(terms);
    int i = 0;
    for (double* v :
         {&forces.strain_energy, &forces.damping_power, &j.stored_energy, &j.fracture_dissipated,
          &j.friction_dissipated, &c.work_before.damping, &c.energy, &c.friction_spring_energy,
          &c.work_before.friction, &contact_after.friction, &motion.kinetic_energy,
          &motion.kinetic_energy_half_step, &motion.constraint_work_before,
          &motion.constraint_work_after})
      *v = terms[i++];
    motion.momentum_before = Vec3(terms[14], terms[15], terms[16]);
    motion.momentum_after = Vec3(terms[17], terms[18], terms[19]);
    motion.finite = terms[20] == 0.0;
    bad_tet_ranks = terms[21];
    // A signal on any rank ends the run after this step on every rank (no extra collective).
    if (terms[22] > 0.0) interrupt_ = interrupt_signal() != 0 ? interrupt_signal() : -1;
    crushed_ranks = terms[23];
    detection_due_ = terms[24] > 0.0 ? 1 : 0;
    tunnel_ranks = terms[25];
    contact_after.damping = terms[26];
    boundary_before = terms[27];
    boundary_after = terms[28];
    motion.local_damping_work_before = terms[29];
    motion.local_damping_work_after = terms[30];
    reduction_seconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  // Energy balance at t_n
  energy.strain = forces.strain_energy;
  if (plan_.joints) {
    energy.joint = j.stored_energy;
    // The joints' dissipation covers x_{n-1} -> x_n, so all of it is "before" work at t_n.
    energy.dissipated_fracture = ledger_.fracture.add(j.fracture_dissipated, 0.0);
    energy.dissipated_friction = joint_friction_.add(j.friction_dissipated, 0.0);
  }
  if (plan_.contact) {
    // What friction took from the bodies (trapezoid work, as the integrator sees it) is stored in
    // the stick springs or dissipated: slip, and springs released when a contact ends.
    energy.contact = c.energy + c.friction_spring_energy;
    energy.dissipated_friction +=
        ledger_.friction.add(c.work_before.friction, contact_after.friction) -
        c.friction_spring_energy;
  }
  energy.kinetic = motion.kinetic_energy;
  kinetic_half_step_ = motion.kinetic_energy_half_step;
  // Gravity potential = − its trapezoid work, ½dt·g·(Σm·v⁻ + Σm·v⁺) per step: exact for a constant
  // g (−Σ m g·(x − x0)) and right when g changes in time (tilting tables).
  if (plan_.gravity)
    energy.gravity = -ledger_.gravity.add(0.5 * dt_ * model_.gravity.dot(motion.momentum_before),
                                          0.5 * dt_ * model_.gravity.dot(motion.momentum_after));
  const double viscous_step = forces.damping_power * dt_;  // element damping, J
  // Element and contact dashpots, and the local damping of a quasi-static run (its work is ≤ 0).
  energy.dissipated_damping = ledger_.damping.add(
      0.5 * viscous_step + c.work_before.damping - motion.local_damping_work_before,
      0.5 * viscous_step + contact_after.damping - motion.local_damping_work_after);
  energy.external_work =
      ledger_.external.add(motion.constraint_work_before, motion.constraint_work_after);
  if (absorbing_)
    energy.dissipated_boundary = ledger_.boundary.add(boundary_before, boundary_after);
  ledger_.record(energy);
  // Work through t_n+½ counts too: the plain kinetic energy already holds the half step after t_n.
  energy_input_ =
      std::max({energy_input_, std::abs(ledger_.initial_total()), std::abs(energy.external_work),
                std::abs(ledger_.external.through_previous), std::abs(energy.gravity),
                std::abs(ledger_.gravity.through_previous), energy_floor_});
  // An inverted or NaN tet is seen by the ranks that hold it: when any rank has one (counted in
  // the reduction above), the check runs collectively and every rank stops with that rank's
  // message.  The other checks use reduced values, so every rank decides alike without one.
  if (distribution_ && bad_tet_ranks > 0)
    comm_->run_collectively([&] { check_state(forces, motion.finite); });
  else
    check_state(forces, motion.finite);
  // Tunnelling first: a body that jumped an element in one step also deforms the tets that hold
  // ghost copies of its nodes (not yet exchanged), which the minimum-step guard would report.
  if (distribution_ && tunnel_ranks > 0)
    comm_->run_collectively([&] { check_tunnelling(travel); });
  else if (tunnel_ranks > 0)
    check_tunnelling(travel);
  if (distribution_ && crushed_ranks > 0)
    comm_->run_collectively([&] { check_stable_step(deformed); });
  else if (step_too_large)
    check_stable_step(deformed);

  if (!distribution_) interrupt_ = interrupt_signal();
  time_ += dt_;
  ++steps_;
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
void Simulation::check_tunnelling(const NodeTravel& travel) const {
  if (!(travel.step > tunnel_size_) || travel.fastest < 0) return;
  const NodeArrays& nodes = model_.nodes;
  const LocalIndex n = travel.fastest;
  const std::int32_t piece = nodes.piece[n];
  const double speed = travel.step / dt_;
  std::ostringstream msg;
  msg << "numerical failure at step " << steps_ << " (t = " << time_ << " s): node " << nodes.gid[n]
      << " of body '" << model_.body_names[model_.pieces.body_of(piece)] << "' (piece "
      << model_.pieces.index_in_body(piece) << ") moved " << travel.step << " m in one step (speed "
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

RunReport Simulation::report() const {
  RunReport r;
  r.steps = steps_;
  r.time = time_;
  r.time_step = dt_;
  r.critical_time_step = dt_critical_;
  r.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
  r.energy = ledger_.current();
  r.balance_error = ledger_.balance_error();
  for (const auto& c : clocks_) r.stages.push_back(c);
  r.pieces = static_cast<long>(model_.pieces.size());
  // Counts of what this rank owns (joints: by their tet A), summed over the ranks below.
  std::vector<std::int64_t> counts = {model_.nodes.n_owned, 0, 0, 0, 0, 0, 0};
  for (LocalIndex t = 0; t < model_.tets.size(); ++t) counts[1] += model_.tets.is_owned(t);
  const JointArrays& joint_rows = model_.joints;
  for (LocalIndex i = 0; i < joint_rows.size(); ++i) {
    if (!model_.tets.is_owned(joint_rows.tets[2 * i])) continue;
    ++counts[2];
    const double f_t =
        model_.joint_laws[static_cast<std::size_t>(joint_rows.law[i])].fracture.tensile_strength;
    r.joint_tensile_min = std::min(r.joint_tensile_min, f_t);
    r.joint_tensile_max = std::max(r.joint_tensile_max, f_t);
    if (!joint_rows.broken[i]) continue;
    ++counts[3];
    const auto mode = static_cast<FailureMode>(joint_rows.mode[i]);
    ++counts[4 + (mode == FailureMode::tension ? 0 : mode == FailureMode::shear ? 1 : 2)];
  }
  std::vector<std::int64_t> memory = {startup_peak_rss_kib_, peak_rss_kib()};
  r.startup_peak_rss_kib_max = r.startup_peak_rss_kib_mean = memory[0];
  r.run_peak_rss_kib_max = r.run_peak_rss_kib_mean = memory[1];
  // Largest gids held (every rank's are the model's, ghosts included).
  const auto last = [](const std::vector<GlobalId>& gids) {
    return gids.empty() ? GlobalId{-1} : *std::max_element(gids.begin(), gids.end());
  };
  std::vector<std::int64_t> gid_max = {last(model_.nodes.gid), last(model_.tets.gid),
                                       last(model_.joints.gid)};
  r.gid_offset = model_.gid_offset;
  r.initial_equilibrium_residual = initial_residual_;
  if (distribution_) {
    std::vector<std::int64_t> largest = memory;
    largest.insert(largest.end(), gid_max.begin(), gid_max.end());
    comm_->max_in_place(largest);
    std::copy(largest.begin() + 2, largest.end(), gid_max.begin());
    comm_->sum_in_place(memory);
    r.startup_peak_rss_kib_max = largest[0];
    r.run_peak_rss_kib_max = largest[1];
    r.startup_peak_rss_kib_mean = memory[0] / comm_->size();
    r.run_peak_rss_kib_mean = memory[1] / comm_->size();
    comm_->sum_in_place(counts);
    r.ranks = comm_->size();
    r.state_hash = hash_to_hex(global_state_hash(model_, *comm_));
    r.joint_strength_hash = hash_to_hex(comm_->sum(joint_strength_hash(model_)));
    r.joint_tensile_min = comm_->min(r.joint_tensile_min);
    r.joint_tensile_max = comm_->max(r.joint_tensile_max);
    r.fragments = global_fragment_count(model_, *comm_);
    const DistributionReport& d = distribution_->report();
    r.parallel = true;
    r.start = distributed_start_ ? "distributed" : "whole_model";
    r.imbalance = d.imbalance;
    r.max_imbalance = d.max_imbalance;
    r.redistributions = d.cycles;
    r.rebalances = d.rebalances;
    r.migrated_elements = d.migrated_tets;
    r.halo_elements_max = d.halo_tets_max;
    r.ghost_nodes_max = d.ghost_nodes_max;
    r.ghost_nodes_mean = d.ghost_nodes_sum / comm_->size();
    r.neighbours_max = d.neighbours_max;
    r.active_elements_max = comm_->max(static_cast<std::int64_t>(model_.tet_force_order.size()));
    r.communication_seconds =
        clocks_[halo].seconds + clocks_[migration].seconds + reduction_seconds_;
  } else {
    r.state_hash = hash_to_hex(state_hash(model_.nodes, model_.gid_offset));
    r.joint_strength_hash = hash_to_hex(joint_strength_hash(model_));
    r.fragments = count_fragments(model_);
  }
  r.node_gid_max = gid_max[0];
  r.tet_gid_max = gid_max[1];
  r.joint_gid_max = gid_max[2];
  r.nodes = counts[0];
  r.elements = counts[1];
  r.joints = counts[2];
  r.broken_joints = counts[3];
  for (int m = 0; m < 3; ++m) r.broken_by_mode[m] = counts[4 + m];
  return r;
}

void Simulation::write_outputs(bool force) {
  if (!files_) return;
  Timed timed(clocks_[output]);
  mark_phase(CommPhase::output);
  // Energy rows refer to t_n = time_ − dt (the state the ledger recorded).
  const double energy_time = steps_ > 0 ? time_ - dt_ : 0.0;
  const double energy_every =
      scene_.output.energy_every > 0 ? scene_.output.energy_every : scene_.output.every;
  const bool energy_row = steps_ > 0 && (force || energy_time >= next_energy_time_ - 1e-12 * dt_);
  if (energy_row) {
    if (energy_every > 0)
      next_energy_time_ =
          next_output_time(next_energy_time_, energy_time + 1e-12 * dt_, energy_every);
    else
      next_energy_time_ = scene_.time.end;
  }
  const bool frame = force || time_ >= next_frame_time_ - 1e-12 * dt_;
  if (frame) {
    if (scene_.output.every > 0)
      next_frame_time_ =
          next_output_time(next_frame_time_, time_ + 1e-12 * dt_, scene_.output.every);
    else
      next_frame_time_ = scene_.time.end;
  }
  if (energy_row || frame) write_files(frame, energy_row, energy_time);
  if (histories_) histories_->write(options_.output_dir);  // the row of this step, if it took one
  const double every = scene_.output.checkpoint_every;
  if (comm_ && every > 0 && steps_ > 0 && time_ >= next_checkpoint_time_ - 1e-12 * dt_) {
    next_checkpoint_time_ = next_output_time(next_checkpoint_time_, time_ + 1e-12 * dt_, every);
    mark_phase(CommPhase::checkpoint);
    write_checkpoint();
  }
  mark_phase(CommPhase::step);
}

// The energy row and/or the frame (with contacts, cracks and bodies.csv rows) of this step.
void Simulation::write_files(bool frame, bool energy_row, double energy_time) {
  // Piece motions: of every piece on one rank; on N ranks of this rank's directory block.
  BlockMotions motion;
  if (frame) {
    if (distribution_) {
      if (halo_in_flight_) {  // frames show ghost nodes of owned tets: complete the exchange
        distribution_->finish_halo_exchange(model_.nodes);
        halo_in_flight_ = false;
      }
      motion = directory_piece_motions(model_, *comm_);
    } else {
      motion.motion = piece_motions(model_);
    }
  }
  // The frame first: with output.format xdmf it is written collectively, so no rank may leave
  // this lambda before it (rank 0 alone failing on energy.csv would leave the others waiting in
  // the frame's collectives).
  const auto write = [&] {
    if (frame)
      files_->write_frame(
          time_, model_, {}, plan_.joints,
          distribution_ ? distribution_->node_owners() : std::vector<std::int32_t>{});
    if (energy_row)
      files_->write_energy_row(energy_time, ledger_.current(), ledger_.balance_error());
    if (!frame) return;
    if (contact_) files_->write_contacts(time_, contact_->records());
    if (!distribution_) files_->write_bodies_rows(time_, model_, motion.motion);
  };
  // A full disk is seen by the ranks that write: every rank stops together (IoError).
  if (!distribution_) return write();
  comm_->run_collectively(write);
  // Collective (MPI-IO), so outside the lambda: every rank reaches it.
  if (frame) files_->write_bodies_rows(time_, model_, motion.first, motion.motion, *comm_);
}

// After a signal: the frame and energy row of the step reached, a checkpoint to continue from.
void Simulation::finish_interrupted(RunReport& result) {
  write_outputs(true);
  if (comm_ && scene_.output.checkpoint_every > 0 && checkpoint_step_ != steps_) write_checkpoint();
  result = report();
  result.status = "interrupted";
  std::ostringstream reason;
  reason << "interrupted by " << (interrupt_ > 0 ? signal_name(interrupt_) : "a signal")
         << (interrupt_ > 0 ? "" : " received by another rank") << " at step " << steps_
         << " (t = " << time_ << " s); ";
  if (checkpoint_step_ == steps_)
    reason << "continue with --restart " << checkpoints_.back();
  else
    reason << "no checkpoint written (output.checkpoint_every is 0)";
  result.reason = reason.str();
}

// summary.json whenever the disk allows; when it does not, the run's status says so.
void Simulation::write_summary(RunReport& result) {
  const auto write = [&] { files_->write_summary(result, model_, scene_.name); };
  try {
    if (distribution_)
      comm_->run_collectively(write);
    else
      write();
  } catch (const IoError& failure) {
    if (result.status == "completed" || result.status == "interrupted") {
      result.status = "failed";
      result.io_failure = true;
      result.reason = std::string("I/O failure: ") + failure.what();
    } else if (is_root()) {
      std::fprintf(stderr, "fdem: summary.json not written either: %s\n", failure.what());
    }
  }
}

RunReport Simulation::run() {
  wall_start_ = std::chrono::steady_clock::now();
  if (options_.write_output) {
    std::optional<XdmfFrames> xdmf;
    const auto frame_format = [&] {  // a bad FDEM_MPIIO_HINTS stops every rank with one message
      if (scene_.output.format == OutputSpec::FrameFormat::xdmf)
        xdmf = XdmfFrames{
            comm_, merge_mpi_io_hints(scene_.output.mpi_io_hints, std::getenv("FDEM_MPIIO_HINTS"))};
    };
    if (comm_)
      comm_->run_collectively(frame_format);
    else
      frame_format();
    if (comm_)  // rank 0 creates the directory first: every rank writes its frame pieces there
      comm_->run_collectively([&] {
        if (comm_->rank() == 0)
          files_ = std::make_unique<RunFiles>(options_.output_dir, scene_.output.fields, 0,
                                              comm_->size(), xdmf);
      });
    if (!files_)
      files_ =
          std::make_unique<RunFiles>(options_.output_dir, scene_.output.fields,
                                     comm_ ? comm_->rank() : 0, comm_ ? comm_->size() : 1, xdmf);
  }
  const long total_steps = checked_step_count(0.0, scene_.time.end, dt_);
  RunReport result;
  ProgressReport progress(options_.quiet || !is_root(), ProgressReport::stderr_is_terminal());
  try {
    write_outputs(true);
    while (steps_ < total_steps && interrupt_ == 0) {
      step();
      write_outputs(steps_ == total_steps);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
      progress.after_step({steps_, total_steps, time_, dt_, ledger_.balance_error(), wall},
                          steps_ == total_steps);
    }
    mark_phase(CommPhase::finish);
    if (steps_ < total_steps) {
      progress.end_line();
      finish_interrupted(result);
    } else {
      result = report();
      result.status = "completed";
    }
  } catch (const NumericalFailure& failure) {
    progress.end_line();
    mark_phase(CommPhase::finish);
    result = report();
    result.status = "failed";
    result.reason = failure.what();
  } catch (const IoError& failure) {
    progress.end_line();
    result = report();
    result.status = "failed";
    result.io_failure = true;
    result.reason = std::string("I/O failure: ") + failure.what();
  }
  if (files_) write_summary(result);
  if (!options_.quiet && is_root()) {
    std::fprintf(stderr, "\n%-20s %12s %10s %8s\n", "stage", "seconds", "calls", "share");
    double total = 0.0;
    for (const auto& c : result.stages) total += c.seconds;
    for (const auto& c : result.stages)
      if (c.calls > 0)
        std::fprintf(stderr, "%-20s %12.4f %10ld %7.1f%%\n", c.name.c_str(), c.seconds, c.calls,
                     total > 0 ? 100.0 * c.seconds / total : 0.0);
    std::fprintf(
        stderr, "wall %.3f s, %ld steps, %.3g element-steps/s, energy balance error %.2e\n",
        result.wall_seconds, result.steps,
        result.wall_seconds > 0 ? double(result.elements) * result.steps / result.wall_seconds
                                : 0.0,
        result.balance_error);
    if (result.parallel)
      std::fprintf(stderr,
                   "%d ranks (%s start): imbalance %.3f (max %.3f), %ld redistributions, %ld "
                   "re-partitions, %ld elements migrated, halo up to %ld elements / %ld ghost "
                   "nodes, communication %.3f s\n",
                   result.ranks, result.start.c_str(), result.imbalance, result.max_imbalance,
                   result.redistributions, result.rebalances, result.migrated_elements,
                   result.halo_elements_max, result.ghost_nodes_max, result.communication_seconds);
  }
  return result;
}

bool distributed_start_possible(const Scene& scene) {
  return scene.parallel.distributed_start;
}

std::unique_ptr<Simulation> make_simulation(const Scene& scene, RunOptions options,
                                            const Communicator* comm) {
  // Memory before any mesh is generated (from the specs), then on the built model (file meshes
  // are only known once read).  Ranks on different nodes may see different ceilings: decided
  // collectively.
  const int ranks = comm ? comm->size() : 1;
  const int ranks_on_node = comm ? comm->ranks_on_this_node() : 1;
  const bool distributed = ranks > 1 && distributed_start_possible(scene);
  const auto check_memory = [&](const ModelSize& size, const char* what) {
    if (comm && comm->size() > 1)
      comm->run_collectively(
          [&] { check_memory_limit(scene, size, ranks, ranks_on_node, distributed, what); });
    else
      check_memory_limit(scene, size, ranks, ranks_on_node, distributed, what);
  };
  check_memory(estimate_generated_size(scene), "the generated meshes");
  if (!comm || comm->size() == 1) {
    Model model = build_model(scene, load_body_meshes(scene));
    check_memory(model_size(model), "the model");
    return std::make_unique<Simulation>(scene, std::move(model), std::move(options), comm);
  }
  if (distributed) {
    // Each rank generates its chunks of the meshes and keeps its block
    // (parallel/distributed_build).
    // A file mesh: each rank reads its slice of the model file (a Gmsh file is prepared into one
    // first), then its size is checked as the generated meshes' was.
    std::vector<BodyChunks> chunks(scene.bodies.size());
    comm->run_collectively([&] {
      for (std::size_t b = 0; b < scene.bodies.size(); ++b)
        if (scene.bodies[b].mesh.kind != MeshSpec::Kind::file)
          chunks[b] = body_chunks(scene.bodies[b].mesh, comm->size());
    });
    ModelSize size = estimate_generated_size(scene);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
      const MeshSpec& mesh = scene.bodies[b].mesh;
      if (mesh.kind != MeshSpec::Kind::file) continue;
      chunks[b] = file_mesh_chunks(model_file_for(mesh, options.output_dir, *comm), mesh.physical,
                                   mesh_source(mesh), *comm);
      size.nodes += static_cast<double>(chunks[b].n_nodes);
      for (std::int64_t tets : chunks[b].chunk_tets) size.tets += static_cast<double>(tets);
    }
    if (size.tets > estimate_generated_size(scene).tets) check_memory(size, "the meshes");
    DistributedModel start = build_distributed_model(scene, chunks, *comm);
    chunks.clear();
    double buffer = 0.0;  // contact buffer (m): as the contact stage sets it on one rank
    if (ContactStage::needed(start.model)) {
      buffer = scene.contact_buffer;
      if (buffer < 0)
        buffer = ContactStage::auto_buffer(
            distributed_nth_value(ContactStage::tet_sizes(start.model), start.n_tets / 2, *comm));
    }
    const DistributionSettings settings = distribution_settings(scene.parallel);
    Model local;
    TravellingState local_state;
    auto distribution = std::make_unique<Distribution>(*comm, settings, std::move(start), buffer,
                                                       local, local_state);
    return std::make_unique<Simulation>(scene, std::move(local), std::move(options), comm,
                                        std::move(distribution), buffer,
                                        std::move(local_state.tet_joint_state));
  }
  // Every rank builds the same whole model; a bad scene or mesh stops every rank with the message.
  // What the constructor checks before distributing is decided from that same model, so every
  // rank throws alike there.
  Model model;
  comm->run_collectively([&] { model = build_model(scene, load_body_meshes(scene)); });
  check_memory(model_size(model), "the model");
  return std::make_unique<Simulation>(scene, std::move(model), std::move(options), comm);
}

}  // namespace fdem
