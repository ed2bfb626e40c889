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
#include "contact/corner_contact.hpp"
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
#include "drivers/step_domain.hpp"
#include "fracture/joint_kernels.hpp"
#include "fracture/joint_stage.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/communicator.hpp"
#include "parallel/contact_faces_exchange.hpp"
#include "parallel/distribution.hpp"
#include "parallel/file_mesh_chunks.hpp"
#include "parallel/piece_directory.hpp"

namespace fdem {

namespace {

// The distribution's settings from the scene's `parallel` block.
DistributionSettings distribution_settings(const ParallelSpec& spec) {
  DistributionSettings settings;
  settings.rebalance_threshold = spec.rebalance_threshold;
  settings.partitioner = spec.partitioner == "rcb"    ? GeometricMethod::rcb
                         : spec.partitioner == "hsfc" ? GeometricMethod::hsfc
                                                      : GeometricMethod::rib;
  settings.random_parts = spec.partitioner == "random";
  settings.incremental = spec.migration == "incremental";
  settings.measured_repartition = spec.repartition == "measured";
  return settings;
}

}  // namespace

std::vector<std::string> StagePlan::describe() const {
  std::vector<std::string> s;
  s.push_back("internal forces (tetrahedra)");
  s.push_back(joints ? "joint forces + fracture" : "joint forces: skipped (no joints)");
  s.push_back(contact ? "contact detection + contact forces"
                      : "contact: skipped (no contact partners)");
  s.push_back(std::string("external forces: ") +
              (gravity ? "gravity (its weights start the internal forces' sums)" : "none") +
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
  plan_.kinematic_loads = scene_.prescribes_velocities();
  plan_.surface_loads = loads_->has_surface_loads();
  check_load_targets(distributed);

  // On N ranks from the distributed start a rank may hold no tet (more ranks than tets at the
  // start, or a body's tets all elsewhere): every rank runs the contact stages when any needs them.
  plan_.contact = distributed ? comm_->max(std::int32_t{ContactStage::needed(model_)}) > 0
                              : ContactStage::needed(model_);
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
    ContactSettings settings{distributed ? contact_buffer : scene_.contact_buffer,
                             scene_.contact_skip_enclosed,
                             scene_.contact_exact_narrowing,
                             scene_.contact_friction_anchor_lag,
                             scene_.contact_body_dashpot,
                             scene_.contact_sliver_tolerance,
                             scene_.contact_clip_replay,
                             uses_corner_contact(scene_)};
    if (settings.corners && scene_.quasi_static.enabled())
      settings.least_damping_ratio = kCornerDampingRatio;
    contact_ = std::make_unique<ContactStage>(model_, settings);
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
    release(model_.tets.enclosed);  // start-up only: the contact stage's joint state carries it
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
  if (scene_.output.histories.enabled &&
      (options_.write_output || scene_.output.histories.stops_runs()))
    histories_ = std::make_unique<HistoryRecorder>(scene_, model_, comm_);
  // A restart overwrites the state of the model (and of the stages) with the checkpoint's.
  if (!options_.restart_path.empty()) {
    mark_phase(CommPhase::restart);
    restore_checkpoint(options_.restart_path);
    moved_since_halo_ = true;  // the halo was made for the start positions
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
  // The ranks the step runs on: one rank is a domain of its own (no ghosts, nothing moves).
  if (distribution_) {
    domain_ = distributed_domain(*comm_, *distribution_);
  } else {
    domain_ = one_rank_domain();
    build_internal_force_split(model_, split_);
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

Simulation::~Simulation() = default;

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
      finish_halo_exchange();  // frames show ghost nodes of owned tets: complete the exchange
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
          time_, model_, {}, plan_.joints ? joints_.get() : nullptr,
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
    const double ratio = scene_.quasi_static.equilibrium_ratio;
    bool equilibrium = false, stopped = false;
    while (steps_ < total_steps && interrupt_ == 0 && !equilibrium && !stopped) {
      step();
      // NaN (undamped): no; and not while a load still changes
      equilibrium = ratio > 0.0 && time_ >= loads_->settle().time && force_ratio_ < ratio;
      stopped = histories_ && histories_->settle();  // a monitor's stop_displacement
      const bool last = steps_ == total_steps || equilibrium || stopped;
      write_outputs(last);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
      progress.after_step({steps_, total_steps, time_, dt_, ledger_.balance_error(), wall}, last);
    }
    mark_phase(CommPhase::finish);
    if (stopped) {
      progress.end_line();
      result = report();
      result.status = "completed";
      result.reason = histories_->stop_reason() + " (step " + std::to_string(steps_) + ")";
    } else if (equilibrium) {
      progress.end_line();
      result = report();
      result.status = "completed";
      std::ostringstream reason;
      reason << "equilibrium at step " << steps_ << " (t = " << time_
             << " s): unbalanced force ratio " << force_ratio_
             << " < quasi_static.equilibrium_ratio " << ratio;
      result.reason = reason.str();
    } else if (steps_ < total_steps) {
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
    // Decided alike on every rank: what follows is collective.
    const bool contact = comm->max(std::int32_t{ContactStage::needed(start.model)}) > 0;
    if (contact && uses_corner_contact(scene))  // as build_model does on one rank
      comm->run_collectively([&] { compute_contact_faces(start.model, *comm); });
    double buffer = 0.0;  // contact buffer (m): as the contact stage sets it on one rank
    if (contact) {
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
