#include "drivers/histories.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "core/history_sums.hpp"
#include "drivers/output_times.hpp"
#include "parallel/communicator.hpp"
#include "parallel/exact_sum_reduction.hpp"

namespace fdem {

namespace {

constexpr int group_sums = 7;     // Σm, Σm·u (3), force (3)
constexpr int monitor_sums = 12;  // u (3), v (3), σ (6)
const char* const group_columns[] = {"ux", "uy", "uz", "fx", "fy", "fz"};
const char* const monitor_columns[] = {"ux",  "uy",  "uz",  "vx",  "vy",  "vz",
                                       "sxx", "syy", "szz", "syz", "sxz", "sxy"};
// Voigt order of the stress columns: (row, column) of σ.
constexpr int voigt[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};

void add_group(std::vector<ExactSum>::iterator at, const GroupSums& g) {
  *at++ = g.mass;
  for (const ExactSum& s : g.moment) *at++ = s;
  for (const ExactSum& s : g.force) *at++ = s;
}

}  // namespace

HistoryRecorder::HistoryRecorder(const Scene& scene, const Model& model, const Communicator* comm)
    : comm_(comm && comm->size() > 1 ? comm : nullptr) {
  const HistoriesSpec& spec = scene.output.histories;
  stops_runs_ = spec.stops_runs();
  // Default interval: the energy rows' (energy_every, else every); 0 there means every step.
  every_ = spec.every >= 0.0                 ? spec.every
           : scene.output.energy_every > 0.0 ? scene.output.energy_every
                                             : scene.output.every;
  for (const int l : spec.loads) {
    loads_.push_back(scene.loads[static_cast<std::size_t>(l)]);
    if (loads_.back().name.empty()) loads_.back().name = "load" + std::to_string(l);
    for (const char* c : group_columns) columns_.push_back("load." + loads_.back().name + "." + c);
  }
  for (const int b : spec.bodies) {
    bodies_.push_back(b);
    for (const char* c : group_columns)
      columns_.push_back("body." + scene.bodies[static_cast<std::size_t>(b)].name + "." + c);
  }
  // Each monitor's tet: the lowest gid holding the point over all ranks (one min-reduction).
  std::vector<std::int64_t> tet;
  for (const MonitorSpec& m : spec.monitors) {
    const GlobalId t = owned_tet_holding(model, m.point);
    tet.push_back(t >= 0 ? t : std::numeric_limits<std::int64_t>::max());
  }
  if (comm_) comm_->min_in_place(tet);
  const auto check = [&] {
    for (std::size_t i = 0; i < tet.size(); ++i) {
      if (tet[i] != std::numeric_limits<std::int64_t>::max()) continue;
      const MonitorSpec& m = spec.monitors[i];
      std::ostringstream msg;
      msg << m.where << ": monitor '" << m.name << "' at (" << m.point.x() << ", " << m.point.y()
          << ", " << m.point.z()
          << ") m lies in no tetrahedron of the model at t = 0; monitors are placed in the "
             "reference configuration: give a point inside a body (or on its surface)";
      throw InputError(msg.str());
    }
  };
  if (comm_)
    comm_->run_collectively([&] {
      if (comm_->rank() == 0) check();  // every rank knows; one message
    });
  else
    check();
  for (std::size_t i = 0; i < tet.size(); ++i) {
    monitors_.push_back({spec.monitors[i], tet[i]});
    for (const char* c : monitor_columns)
      columns_.push_back("monitor." + spec.monitors[i].name + "." + c);
  }
}

std::vector<std::string> monitors_held_at_rest(const Scene& scene, const Model& model) {
  std::vector<std::string> out;
  const TetArrays& tets = model.tets;
  for (const MonitorSpec& m : scene.output.histories.monitors) {
    if (!(m.stop_displacement > 0.0)) continue;
    const GlobalId gid = owned_tet_holding(model, m.point);
    const LocalIndex t = gid >= 0 ? tets.find(gid) : -1;
    if (t < 0) continue;  // in no tet: refused when the simulation was made
    const std::int32_t body = model.pieces.body_of(tets.piece[t]);
    if (!model.body_fixed[static_cast<std::size_t>(body)]) continue;
    bool moved = false;
    for (const LoadSpec& load : scene.loads)
      for (int c = 0; c < 4 && load.prescribes_velocity(); ++c)
        moved =
            moved || load_holds_node(load, model, tets.nodes[4 * static_cast<std::size_t>(t) + c]);
    if (!moved)
      out.push_back("monitor '" + m.name + "' lies in fixed body '" +
                    scene.bodies[static_cast<std::size_t>(body)].name + "'");
  }
  return out;
}

bool HistoryRecorder::due(double time, double dt) const {
  return every_ <= 0.0 || time >= next_time_ - 1e-12 * dt;
}

void HistoryRecorder::sample(const Model& model, double time, double dt) {
  if (every_ > 0.0) next_time_ = next_output_time(next_time_, time + 1e-12 * dt, every_);
  sums_.assign(group_sums * (loads_.size() + bodies_.size()) + monitor_sums * monitors_.size(),
               ExactSum{});
  auto at = sums_.begin();
  for (const LoadSpec& load : loads_) {
    GroupSums g;
    add_load_sums(load, model, dt, g);
    add_group(at, g);
    at += group_sums;
  }
  for (const std::int32_t body : bodies_) {
    GroupSums g;
    add_body_sums(body, model, g);
    add_group(at, g);
    at += group_sums;
  }
  // A monitor's values come from the rank that owns its tet; the other ranks add nothing.
  for (const Monitor& m : monitors_) {
    const LocalIndex t = model.tets.find(m.tet);
    if (t >= 0 && model.tets.is_owned(t)) {
      const MonitorValues v = monitor_values(model, t, m.spec.point);
      for (int k = 0; k < 3; ++k) at[k].add(v.displacement[k]);
      for (int k = 0; k < 3; ++k) at[3 + k].add(v.velocity[k]);
      for (int k = 0; k < 6; ++k) at[6 + k].add(v.stress(voigt[k][0], voigt[k][1]));
    }
    at += monitor_sums;
  }
  pending_ = true;
  pending_time_ = time;
}

std::vector<double> HistoryRecorder::reduce_row() {
  if (comm_) reduce_exact_sums_to_root(sums_, *comm_);
  pending_ = false;
  std::vector<double> row = {pending_time_};
  auto at = sums_.begin();
  for (std::size_t g = 0; g < loads_.size() + bodies_.size(); ++g, at += group_sums) {
    const double mass = at[0].value();
    for (int k = 0; k < 3; ++k) row.push_back(mass > 0.0 ? at[1 + k].value() / mass : 0.0);
    for (int k = 0; k < 3; ++k) row.push_back(at[4 + k].value());
  }
  for (std::size_t m = 0; m < monitors_.size(); ++m, at += monitor_sums)
    for (int k = 0; k < monitor_sums; ++k) row.push_back(at[k].value());
  return row;
}

std::string HistoryRecorder::header() const {
  std::string h = "time";
  for (const std::string& c : columns_) h += "," + c;
  return h + "\n";
}

bool HistoryRecorder::settle() {
  if (!pending_) return false;
  row_ = reduce_row();
  settled_ = true;
  if (!stops_runs_) return false;  // (no reduction for it)
  // The first monitor (in the scene's order) at or beyond its stop: decided on rank 0, which
  // holds the whole row, and sent to every rank with its distance (m).
  double stop[2] = {-1.0, 0.0};  // monitor index, distance
  const std::size_t first_monitor = 1 + 6 * (loads_.size() + bodies_.size());
  for (std::size_t m = 0; m < monitors_.size() && stop[0] < 0.0; ++m) {
    const double limit = monitors_[m].spec.stop_displacement;
    const double* u = row_.data() + first_monitor + monitor_sums * m;
    const double distance = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (limit > 0.0 && distance >= limit) {
      stop[0] = static_cast<double>(m);
      stop[1] = distance;
    }
  }
  if (comm_) {
    std::vector<double> sent(stop, stop + 2);
    if (comm_->rank() != 0) sent = {-1.0, 0.0};
    comm_->max_in_place(sent);
    std::copy(sent.begin(), sent.end(), stop);
  }
  if (stop[0] < 0.0) return false;
  const MonitorSpec& m = monitors_[static_cast<std::size_t>(stop[0])].spec;
  std::ostringstream reason;
  reason << "stopped at t = " << row_[0] << " s: monitor '" << m.name << "' has moved " << stop[1]
         << " m, at least its stop_displacement " << m.stop_displacement << " m";
  stop_reason_ = reason.str();
  return true;
}

void HistoryRecorder::write(const std::string& directory) {
  settle();
  if (!settled_) return;
  settled_ = false;
  const std::vector<double>& row = row_;
  const auto append = [&] {
    if (comm_ && comm_->rank() != 0) return;
    const std::string path = (std::filesystem::path(directory) / "histories.csv").string();
    if (!file_.is_open()) {
      file_.open(path);
      file_ << header() << std::setprecision(12);
    }
    for (std::size_t i = 0; i < row.size(); ++i) file_ << (i ? "," : "") << row[i];
    file_ << '\n';
    file_.flush();
    if (!file_) throw IoError("cannot write " + path + " (disk full?)");
  };
  if (comm_)
    comm_->run_collectively(append);
  else
    append();
}

}  // namespace fdem
