// histories.csv (scene output.histories): the reaction and displacement of loads, the
// displacement and resultant force of bodies, and the displacement, velocity and stress at
// monitor points, one row every `every` s.  A row is taken inside the step, after the forces and
// before the integration (core/history_sums), so force and position belong to the same t_n; its
// sums are exact and added over the ranks in a tree (parallel/exact_sum_reduction), so the file
// is the same bytes on any rank count, and a restart continues its rows at the same times.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "core/exact_sum.hpp"
#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

class Communicator;

// The monitors with a stop_displacement that can never move: the tet that holds the point at
// t = 0 lies in a fixed body and no velocity or base-motion load holds any of its nodes, so their
// stop can never end the run.  "monitor 'NAME' lies in fixed body 'BODY'" each; `model` is the
// whole model on one process (fdem check).
std::vector<std::string> monitors_held_at_rest(const Scene& scene, const Model& model);

class HistoryRecorder {
 public:
  // Finds each monitor's tet: the lowest gid whose reference shape holds the point, over all
  // ranks (`comm`: N ranks, collective; nullptr: one process holds the whole model).  A point
  // in no tet is an InputError naming the monitor's key, file line and coordinates.
  HistoryRecorder(const Scene& scene, const Model& model, const Communicator* comm);

  // Whether the step from t_n = `time` (s) takes a row (rows at 0, every, 2 every, ...).
  bool due(double time, double dt) const;
  // Takes this rank's sums of the row at t_n (call between the forces and the integration) and
  // sets the next row's time.
  void sample(const Model& model, double time, double dt);
  bool pending() const { return pending_; }
  // Collective on N ranks: adds the pending row over the ranks (if the step took one) and checks
  // the monitors' stop_displacement on it.  True when a monitor has reached its stop (every rank
  // alike); stop_reason() then says which.
  bool settle();
  std::string stop_reason() const { return stop_reason_; }
  // Collective on N ranks: settles the pending row, and rank 0 appends it to
  // DIRECTORY/histories.csv (made with its header at the first row).  IoError when the file
  // cannot be written (N ranks: on every rank together).
  void write(const std::string& directory);
  // The pending row added over the ranks: time, then one value per column (rank 0; partial on
  // the others).  Collective on N ranks; clears the pending row.
  std::vector<double> reduce_row();

  // Column names after `time`: load.NAME.ux … fz, body.NAME.ux … fz, monitor.NAME.ux … vz,
  // sxx, syy, szz, syz, sxz, sxy.
  const std::vector<std::string>& columns() const { return columns_; }
  std::string header() const;

  double next_time() const { return next_time_; }  // s: checkpoints keep it
  void set_next_time(double t) { next_time_ = t; }

 private:
  struct Monitor {
    MonitorSpec spec;
    GlobalId tet = -1;  // the tet that holds the point at t = 0
  };
  std::vector<LoadSpec> loads_;
  std::vector<std::int32_t> bodies_;
  std::vector<Monitor> monitors_;
  std::vector<std::string> columns_;
  const Communicator* comm_ = nullptr;  // N ranks only
  double every_ = 0.0;                  // s; 0: every step
  double next_time_ = 0.0;
  bool pending_ = false;
  double pending_time_ = 0.0;
  bool settled_ = false;        // row_ holds the last row, not yet written
  std::vector<double> row_;     // added over the ranks (rank 0; partial on the others)
  std::string stop_reason_;     // of the first monitor that reached its stop_displacement
  bool stops_runs_ = false;     // some monitor has a stop_displacement
  std::vector<ExactSum> sums_;  // of the pending row: 7 per load and body, 12 per monitor
  std::ofstream file_;          // rank 0
};

}  // namespace fdem
