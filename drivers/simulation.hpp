// The engine's step loop.  Simulation::step() spells out the stage order of one time step; run()
// adds output, progress and the end-of-run report around it.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/absorbing_boundary.hpp"
#include "core/dynamics.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"
#include "core/scene.hpp"
#include "drivers/loads.hpp"
#include "drivers/run_report.hpp"
#include "drivers/stage_timer.hpp"

namespace fdem {

class SeriesWriter;
class RunFiles;
class Communicator;
class Distribution;
struct TravellingState;
class ContactStage;
class JointStage;
class LoadSchedule;
class HistoryRecorder;
class StepDomain;
struct StepRecord;

struct RunOptions {
  std::string output_dir = "out";
  bool quiet = false;        // no progress line, no stage table
  bool write_output = true;  // VTK frames and CSV/JSON files
  std::string restart_path;  // continue from this checkpoint (needs a communicator)
};

// Which stages the scene needs; the loop runs only these.
struct StagePlan {
  bool internal_forces = true;
  bool joints = false;
  bool contact = false;
  bool gravity = false;
  bool kinematic_loads = false;
  bool absorbing = false;       // viscous absorbing boundaries (core/absorbing_boundary)
  bool initial_stress = false;  // scene `initial_stress:` (core/initial_stress)
  bool surface_loads = false;   // pressure or traction on boundary faces
  std::vector<std::string> describe() const;
};

class Simulation {
 public:
  // `comm`: the ranks that run it together (nullptr or one rank: serial).  On N ranks every rank
  // passes the same whole model; each keeps its part and halo (parallel/distribution.hpp).
  Simulation(Scene scene, Model model, RunOptions options, const Communicator* comm = nullptr);
  // Distributed start (make_simulation): `model` is this rank's part with its halo, made by
  // `distribution` for the contact buffer `contact_buffer` (m); `tet_joint_state`: per local tet
  // its joint state as the distribution delivered it (empty without joints).
  Simulation(Scene scene, Model model, RunOptions options, const Communicator* comm,
             std::unique_ptr<Distribution> distribution, double contact_buffer,
             std::vector<std::uint8_t> tet_joint_state);
  ~Simulation();

  // Runs to scene.time.end (writing outputs); never throws NumericalFailure or IoError: a
  // failure is reported in the returned status and in summary.json (when the disk allows).  A
  // signal (drivers/interrupt.hpp) ends the run after the step it arrived in, with a checkpoint
  // (when checkpoints are enabled) and the status "interrupted".
  RunReport run();

  // One time step (stages 0–8, drivers/simulation_step.cpp).  Throws NumericalFailure on blow-up.
  void step();

  const Model& model() const { return model_; }
  double initial_equilibrium_residual() const { return initial_residual_; }
  // The last step's mean unbalanced-force ratio (quasi_static.equilibrium_ratio); NaN when the
  // step was not damped.
  double unbalanced_force_ratio() const { return force_ratio_; }
  // When the loads stop changing: equilibrium_ratio ends the run only from then on.
  const LoadsSettle& loads_settle() const { return loads_->settle(); }
  const LoadsSettle& base_motion_start() const { return loads_->base_motion_start(); }
  Model& model() { return model_; }
  const Scene& scene() const { return scene_; }
  const StagePlan& plan() const { return plan_; }
  const EnergyLedger& energy() const { return ledger_; }
  double time() const { return time_; }
  long steps_done() const { return steps_; }
  double time_step() const { return dt_; }
  double critical_time_step() const { return dt_critical_; }
  void set_time_step(double dt) { dt_ = dt; }
  const ContactStage* contact_stage() const { return contact_.get(); }
  const JointStage* joint_stage() const { return joints_.get(); }
  RunReport report() const;

 private:
  enum Stage {
    internal,
    joints,
    fracture,
    detection,
    contact,
    external,
    integration,
    halo,
    migration,
    output,
    n_stages
  };
  void check_state(const struct InternalForceSummary& forces, bool velocities_finite) const;
  void check_run_limits() const;
  // Every `absorbing:` entry must select a boundary face somewhere in the model (InputError).
  void check_absorbing_faces(bool distributed) const;
  void check_load_targets(bool distributed) const;
  // Sets initial_residual_: |forces at t = 0| / |initial stress's forces| over free components.
  void check_initial_equilibrium(bool distributed);
  std::vector<double> initial_stress_;  // S0, 6 per local tet (Pa)
  double initial_residual_ = -1.0;      // −1: no initial stress
  std::string step_advice() const;
  void check_stable_step(const struct CriticalStep& deformed) const;
  void check_tunnelling(const struct IntegrationSummary& motion) const;
  std::string step_origin() const;
  // The stages of step(), in its order (drivers/simulation_step.cpp).
  void share_broken_joints();
  bool detection_due();
  bool migration_due(bool detecting) const;
  // `detecting`: a detection at the current positions follows at once (the halo is built for it,
  // and the last detection is not repeated).
  void redistribute(bool detecting);
  void apply_loads();
  void add_internal_forces(StepRecord& r);
  void add_joint_forces(StepRecord& r);
  void detect_contacts();
  void add_contact_forces(StepRecord& r);
  void add_external_forces(StepRecord& r);
  void record_histories();
  void integrate(StepRecord& r);
  void start_halo_exchange();
  void finish_halo_exchange();
  void check_deformed_step(StepRecord& r);
  void sum_over_ranks(StepRecord& r);
  void book_energy(const StepRecord& r);
  void check_step(const StepRecord& r);
  TravellingState travelling_state() const;
  // `detected`: the contact stage has candidates to restore — those that travelled in `state`
  // (`candidates_travelled`), or else the last detection repeated at the positions it saw.
  void rebind_stages(TravellingState& state, bool detected, bool candidates_travelled = false);
  void write_checkpoint();
  void restore_checkpoint(const std::string& path);
  bool is_root() const;
  void write_outputs(bool force);
  void write_files(bool frame, bool energy_row, double energy_time);
  void finish_interrupted(RunReport& result);
  void write_summary(RunReport& result);
  void start_half_step(NodeArrays& nodes) const;

  Scene scene_;
  Model model_;
  RunOptions options_;
  StagePlan plan_;
  EnergyLedger ledger_;
  double time_ = 0.0;
  long steps_ = 0;
  double dt_ = 0.0, dt_critical_ = 0.0;
  double energy_floor_ = 0.0;       // J, see the constructor
  double energy_input_ = 0.0;       // J, largest energy put in so far (see check_state)
  double kinetic_half_step_ = 0.0;  // J, ½m|v_n+½|² of the last step
  bool stop_motion_ = false;        // kinetic damping: the next step stops every free node
  long kinetic_damping_stops_ = 0;  // steps that did
  double force_ratio_ = 0.0;        // unbalanced-force ratio of the last step (NaN: undamped)
  StageClock clocks_[n_stages];
  std::chrono::steady_clock::time_point wall_start_;
  double next_frame_time_ = 0.0, next_energy_time_ = 0.0;
  std::unique_ptr<RunFiles> files_;
  std::unique_ptr<ContactStage> contact_;
  std::unique_ptr<JointStage> joints_;
  std::unique_ptr<LoadSchedule> loads_;           // time-dependent loads (drivers/loads)
  std::unique_ptr<AbsorbingBoundary> absorbing_;  // scene `absorbing:` only
  std::unique_ptr<HistoryRecorder> histories_;    // histories.csv (output.histories), with output
  WorkAccumulator joint_friction_;  // Coulomb slip inside joints (part of dissipated_friction)
  const Communicator* comm_ = nullptr;
  std::unique_ptr<Distribution> distribution_;  // N ranks only
  std::unique_ptr<StepDomain> domain_;          // the ranks the step runs on (one or N)
  // Whether the step ahead detects because a node went more than buffer/2 (from the last step's
  // reduction, the same on every rank; −1 unknown: before the first step, after a restart).
  int detection_due_ = -1;
  // A joint broken in the last step, reported by this rank: what every rank needs to know of it.
  struct BrokenJoint {
    GlobalId joint, tet_a, tet_b;
    double time;  // s
    std::int32_t mode, body_a, body_b;
  };
  std::vector<BrokenJoint> own_breaks_;  // this rank's, since the last step's reduction
  bool breaks_pending_ = false;          // some rank broke a joint in the last step
  bool bodies_cracking_ = false;         // ... the first in its body (contact: every rank learns)
  bool moved_since_halo_ = false;        // positions changed since the halo was built
  double busy_at_last_cycle_ = 0.0;  // compute seconds (stage clocks) at the last redistribution
  double tunnel_size_ = 0.0;         // m, smallest tet altitude at the start (contact scenes)
  double reduction_seconds_ = 0.0;
  std::vector<double> reduced_;  // scratch of the step's reduction
  InternalForceSplit split_;     // interior tets computed while the ghost exchange travels
  double next_checkpoint_time_ = 0.0;
  std::vector<std::string> checkpoints_;  // written so far; the last two are kept
  long checkpoint_step_ = -1;             // step of the newest checkpoint written
  long next_stability_check_ = 0;         // step of the next minimum-step guard check
  int interrupt_ = 0;  // signal that ends the run after this step (-1: received by another rank)
  long whole_nodes_ = 0, whole_tets_ = 0, whole_joints_ = 0;  // counts of the whole model
  bool distributed_start_ = false;    // started from build_distributed_model
  std::uint64_t reference_hash_ = 0;  // of the whole model's x0
  long startup_peak_rss_kib_ = 0;     // this rank, end of start-up
};

// Whether N ranks can start the scene without any rank holding the whole model
// (parallel.distributed_start, docs/parallel.md): generated meshes are made chunk by chunk, file
// meshes read slice by slice from a model file (a Gmsh file is prepared into one first), joints
// placed through face and position directories.
bool distributed_start_possible(const Scene& scene);

// Builds a Simulation from a scene file (meshes loaded or generated).
std::unique_ptr<Simulation> make_simulation(const Scene& scene, RunOptions options,
                                            const Communicator* comm = nullptr);

}  // namespace fdem
