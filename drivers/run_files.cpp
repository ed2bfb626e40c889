#include "drivers/run_files.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "drivers/run_report.hpp"
#include "fracture/joint_kernels.hpp"
#include "fracture/joint_stage.hpp"

namespace fdem {

namespace {
std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\')
      out += '\\', out += c;
    else if (c == '\n')
      out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20)
      out += ' ';
    else
      out += c;
  }
  return out;
}

// The -o directory is the user's choice, so failing to create it is an input error (exit 2).
const std::string& create_output_directory(const std::string& directory) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error)
    throw InputError("cannot create the output directory '" + directory +
                     "' (-o): " + error.message());
  return directory;
}

constexpr const char* bodies_header = "time,body,piece,mass,x,y,z,vx,vy,vz,rx,ry,rz\n";

// JSON has no NaN or infinity: a run that blew up reports those values as null.
struct JsonNumber {
  double value;
};
std::ostream& operator<<(std::ostream& out, JsonNumber n) {
  return std::isfinite(n.value) ? out << n.value : out << "null";
}
}  // namespace

RunFiles::RunFiles(const std::string& directory, const std::vector<std::string>& fields, int rank,
                   int ranks, std::optional<XdmfFrames> xdmf)
    : directory_(directory),
      fields_(fields),
      rank_(rank),
      ranks_(ranks),
      frames_(create_output_directory(directory), "frames", rank, ranks),
      xdmf_(std::move(xdmf)) {
  if (xdmf_) xdmf_series_ = std::make_unique<XdmfSeries>(directory, "frames", rank == 0);
  if (rank_ != 0) return;
  energy_.open(std::filesystem::path(directory) / "energy.csv");
  // Columns added after the first release go at the end, so that readers by position still work.
  energy_ << "time,kinetic,strain,gravity,contact,joint,dissipated_fracture,dissipated_friction,"
             "dissipated_damping,external_work,total,balance_error,dissipated_boundary\n";
  bodies_.open(std::filesystem::path(directory) / "bodies.csv");
  bodies_ << bodies_header;
  energy_ << std::setprecision(12);
  if (ranks_ > 1) bodies_.close();  // the rows are appended collectively (OrderedTextFile)
  if (!energy_ || !bodies_)
    throw InputError("cannot write into the output directory '" + directory + "' (-o)");
}

void RunFiles::write_energy_row(double time, const EnergyTerms& e, double balance_error) {
  if (rank_ != 0) return;
  energy_ << time << ',' << e.kinetic << ',' << e.strain << ',' << e.gravity << ',' << e.contact
          << ',' << e.joint << ',' << e.dissipated_fracture << ',' << e.dissipated_friction << ','
          << e.dissipated_damping << ',' << e.external_work << ',' << e.total() << ','
          << balance_error << ',' << e.dissipated_boundary << '\n';
  energy_.flush();
  if (!energy_) throw IoError("cannot write " + directory_ + "/energy.csv (disk full?)");
}

std::string bodies_rows(double time, const Model& model, std::int32_t first_piece,
                        const std::vector<PieceMotion>& motion) {
  std::ostringstream rows;
  rows << std::setprecision(12);
  for (std::size_t i = 0; i < motion.size(); ++i) {
    const std::int32_t id = first_piece + static_cast<std::int32_t>(i);
    const PieceMotion& m = motion[i];
    rows << time << ',' << model.body_names[model.pieces.body_of(id)] << ','
         << model.pieces.index_in_body(id) << ',' << model.pieces[id].mass << ',' << m.centroid.x()
         << ',' << m.centroid.y() << ',' << m.centroid.z() << ',' << m.velocity.x() << ','
         << m.velocity.y() << ',' << m.velocity.z() << ',' << m.rotation.x() << ','
         << m.rotation.y() << ',' << m.rotation.z() << '\n';
  }
  return rows.str();
}

void RunFiles::write_bodies_rows(double time, const Model& model,
                                 const std::vector<PieceMotion>& motion) {
  if (rank_ != 0) return;
  bodies_ << bodies_rows(time, model, 0, motion);
  bodies_.flush();
  if (!bodies_) throw IoError("cannot write " + directory_ + "/bodies.csv (disk full?)");
}

void RunFiles::write_bodies_rows(double time, const Model& model, std::int32_t first_piece,
                                 const std::vector<PieceMotion>& motion, const Communicator& comm) {
  if (!shared_bodies_)
    shared_bodies_ = std::make_unique<OrderedTextFile>(
        (std::filesystem::path(directory_) / "bodies.csv").string(),
        static_cast<std::int64_t>(std::string(bodies_header).size()), comm);
  shared_bodies_->append(bodies_rows(time, model, first_piece, motion));
}

std::vector<double> tet_damage(const Model& model, const JointStage* stage) {
  std::vector<double> damage(model.tets.size(), 0.0);
  if (!stage) return damage;
  const JointArrays& joints = model.joints;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    const double d = joints.broken[j] ? 1.0 : stage->damage(j);
    for (int side = 0; side < 2; ++side) {
      double& slot = damage[joints.tets[2 * j + side]];
      slot = std::max(slot, d);
    }
  }
  return damage;
}

void RunFiles::write_frame(double time, const Model& model, const std::vector<FrameField>& extra,
                           const JointStage* joints, const std::vector<std::int32_t>& node_owner) {
  std::vector<FrameField> fields = extra;
  if (std::find(fields_.begin(), fields_.end(), "damage") != fields_.end())
    fields.push_back({"damage", 1, true, tet_damage(model, joints)});
  if (xdmf_) {
    write_xdmf_tet_frame(time, model, fields, node_owner);
    if (joints) write_cracks(time, model, *joints);
    return;
  }
  const std::string stem = frames_.next_frame_path();
  write_parallel_tet_frame((std::filesystem::path(directory_) / stem).string(), model, fields_,
                           fields, rank_, ranks_);
  frames_.add_frame(time, frames_.frame_file(stem, "vtu"));
  if (joints) write_cracks(time, model, *joints);
}

void RunFiles::write_xdmf_tet_frame(double time, const Model& model,
                                    const std::vector<FrameField>& extra,
                                    const std::vector<std::int32_t>& node_owner) {
  const NodeArrays& nodes = model.nodes;
  XdmfFrameRows rows;
  rows.n_owned = nodes.n_owned;
  rows.node_gid = nodes.gid;
  rows.node_owner = node_owner;
  rows.node_x.assign(nodes.x.begin(), nodes.x.begin() + 3 * std::ptrdiff_t{nodes.n_owned});
  const std::vector<LocalIndex> cells = owned_tets(model.tets);
  rows.tet_nodes.reserve(4 * cells.size());
  for (const LocalIndex t : cells)
    for (int c = 0; c < 4; ++c) rows.tet_nodes.push_back(model.tets.nodes[4 * t + c]);
  const LocalSelection points = LocalSelection::first(static_cast<std::size_t>(nodes.n_owned));
  rows.arrays = tet_frame_columns(model, cells, points, fields_, extra);  // read when written
  const Communicator comm = xdmf_->comm ? *xdmf_->comm : process_communicator();
  const std::string file = xdmf_series_->next_frame_file();
  const FrameFileInfo written = write_xdmf_frame(directory_, file, time, comm, rows, xdmf_->hints);
  // Rank 0 rewrites the .xdmf; a failure there (disk full) stops every rank, not rank 0 alone.
  comm.run_collectively([&] { xdmf_series_->add_frame(written); });
}

void RunFiles::write_cracks(double time, const Model& model, const JointStage& stage) {
  if (!cracks_) cracks_ = std::make_unique<SeriesWriter>(directory_, "cracks", rank_, ranks_);
  const JointArrays& joints = model.joints;
  const double* x = model.nodes.x.data();
  std::vector<double> points;
  std::vector<std::int64_t> triangles;
  std::vector<double> mode, failure_time, opening;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (!joints.broken[j] || !model.tets.is_owned(joints.tets[2 * j])) continue;
    const LocalIndex* id = joints.nodes.data() + 6 * static_cast<std::size_t>(j);
    double gap = 0.0;
    for (int i = 0; i < 3; ++i) {
      triangles.push_back(static_cast<std::int64_t>(points.size() / 3));
      for (int k = 0; k < 3; ++k) points.push_back(x[3 * id[i] + k]);
      gap += (vec3_at(x, id[3 + i]) - vec3_at(x, id[i])).norm() / 3.0;
    }
    mode.push_back(joints.mode[j]);
    failure_time.push_back(stage.failure_time(j));
    opening.push_back(gap);
  }
  const std::string stem = cracks_->next_frame_path();
  write_parallel_triangle_frame((std::filesystem::path(directory_) / stem).string(), points,
                                triangles,
                                {{"mode", 1, true, mode},
                                 {"failure_time", 1, true, failure_time},
                                 {"opening", 1, true, opening}},
                                rank_, ranks_);
  cracks_->add_frame(time, cracks_->frame_file(stem, "vtp"));
}

void RunFiles::write_contacts(double time, const std::vector<ContactRecord>& records) {
  if (!contacts_) contacts_ = std::make_unique<SeriesWriter>(directory_, "contacts", rank_, ranks_);
  std::vector<double> points, normal, tangential;
  for (const ContactRecord& r : records)
    for (int k = 0; k < 3; ++k) {
      points.push_back(r.point[k]);
      normal.push_back(r.normal_force[k]);
      tangential.push_back(r.tangential_force[k]);
    }
  const std::string stem = contacts_->next_frame_path();
  write_parallel_point_frame(
      (std::filesystem::path(directory_) / stem).string(), points,
      {{"normal_force", 3, false, normal}, {"tangential_force", 3, false, tangential}}, rank_,
      ranks_);
  contacts_->add_frame(time, contacts_->frame_file(stem, "vtp"));
}

std::string summary_json(const RunReport& r, const Model& model, const std::string& scene_name) {
  std::ostringstream j;
  j << std::setprecision(15);
  j << "{\n";
  j << "  \"scene\": \"" << json_escape(scene_name) << "\",\n";
  j << "  \"status\": \"" << r.status << "\",\n";
  if (!r.reason.empty()) j << "  \"reason\": \"" << json_escape(r.reason) << "\",\n";
  j << "  \"ranks\": " << r.ranks << ",\n";
  j << "  \"steps\": " << r.steps << ",\n";
  j << "  \"end_time\": " << JsonNumber{r.time} << ",\n";
  j << "  \"time_step\": " << JsonNumber{r.time_step} << ",\n";
  j << "  \"critical_time_step\": " << JsonNumber{r.critical_time_step} << ",\n";
  j << "  \"wall_seconds\": " << JsonNumber{r.wall_seconds} << ",\n";
  j << "  \"nodes\": " << r.nodes << ",\n";
  j << "  \"elements\": " << r.elements << ",\n";
  j << "  \"pieces\": " << model.pieces.size() << ",\n";
  j << "  \"joints\": " << r.joints << ",\n";
  j << "  \"broken_joints\": " << r.broken_joints << ",\n";
  j << "  \"broken_by_mode\": {\"tension\": " << r.broken_by_mode[0]
    << ", \"shear\": " << r.broken_by_mode[1] << ", \"mixed\": " << r.broken_by_mode[2] << "},\n";
  if (r.joints > 0)
    j << "  \"joint_strength\": {\"tensile_min\": " << JsonNumber{r.joint_tensile_min}
      << ", \"tensile_max\": " << JsonNumber{r.joint_tensile_max} << ", \"hash\": \""
      << r.joint_strength_hash << "\"},\n";
  if (r.initial_equilibrium_residual >= 0.0)
    j << "  \"initial_stress\": {\"equilibrium_residual\": "
      << JsonNumber{r.initial_equilibrium_residual} << "},\n";
  if (r.fragments >= 0) j << "  \"fragments\": " << r.fragments << ",\n";
  if (r.kinetic_damping_stops >= 0)
    j << "  \"quasi_static\": {\"kinetic_damping_stops\": " << r.kinetic_damping_stops << "},\n";
  j << "  \"gids\": {\"offset\": " << r.gid_offset << ", \"node_max\": " << r.node_gid_max
    << ", \"tet_max\": " << r.tet_gid_max << ", \"joint_max\": " << r.joint_gid_max << "},\n";
  const MigrationReport& m = r.migration;
  if (r.parallel)
    j << "  \"decomposition\": {\"start\": \"" << r.start
      << "\", \"imbalance\": " << JsonNumber{r.imbalance}
      << ", \"max_imbalance\": " << JsonNumber{r.max_imbalance}
      << ", \"redistributions\": " << r.redistributions << ", \"rebalances\": " << r.rebalances
      << ", \"migrated_elements\": " << r.migrated_elements
      << ", \"halo_elements_max\": " << r.halo_elements_max
      << ", \"ghost_nodes_max\": " << r.ghost_nodes_max
      << ", \"ghost_nodes_mean\": " << r.ghost_nodes_mean
      << ", \"neighbours_max\": " << r.neighbours_max
      << ", \"active_elements_max\": " << r.active_elements_max
      << ", \"ghost_nodes_exchanged_max\": " << r.exchanged_ghosts_max
      << ", \"ghost_nodes_exchanged_mean\": " << r.exchanged_ghosts_mean
      << ", \"incremental_redistributions\": " << m.incremental_cycles
      << ", \"sent_elements\": " << m.sent_tets << ", \"dropped_elements\": " << m.dropped_tets
      << ", \"sent_bytes\": " << m.sent_bytes
      << ", \"measured_imbalance\": " << JsonNumber{m.measured_imbalance}
      << ", \"repartition_seconds\": " << JsonNumber{m.repartition_seconds}
      << ", \"incremental_seconds\": " << JsonNumber{m.incremental_seconds}
      << ", \"predicted_gain_seconds\": " << JsonNumber{m.predicted_gain_seconds}
      << ", \"repartitions_declined\": " << m.repartitions_declined
      << ", \"communication_seconds\": " << JsonNumber{r.communication_seconds} << "},\n";
  j << "  \"memory\": {\"startup_peak_rss_kib_max\": " << r.startup_peak_rss_kib_max
    << ", \"startup_peak_rss_kib_mean\": " << r.startup_peak_rss_kib_mean
    << ", \"run_peak_rss_kib_max\": " << r.run_peak_rss_kib_max
    << ", \"run_peak_rss_kib_mean\": " << r.run_peak_rss_kib_mean << "},\n";
  j << "  \"stages\": {";
  bool first = true;
  for (const auto& s : r.stages) {
    if (s.calls == 0) continue;
    j << (first ? "\n" : ",\n") << "    \"" << s.name
      << "\": {\"seconds\": " << JsonNumber{s.seconds} << ", \"calls\": " << s.calls << "}";
    first = false;
  }
  j << "\n  },\n";
  const double element_steps = static_cast<double>(r.elements) * static_cast<double>(r.steps);
  j << "  \"throughput\": {\"element_steps_per_second\": "
    << JsonNumber{r.wall_seconds > 0 ? element_steps / r.wall_seconds : 0.0} << "},\n";
  const EnergyTerms& e = r.energy;
  j << "  \"energy\": {\"kinetic\": " << JsonNumber{e.kinetic}
    << ", \"strain\": " << JsonNumber{e.strain} << ", \"gravity\": " << JsonNumber{e.gravity}
    << ", \"contact\": " << JsonNumber{e.contact} << ", \"joint\": " << JsonNumber{e.joint}
    << ", \"dissipated_fracture\": " << JsonNumber{e.dissipated_fracture}
    << ", \"dissipated_friction\": " << JsonNumber{e.dissipated_friction}
    << ", \"dissipated_damping\": " << JsonNumber{e.dissipated_damping}
    << ", \"dissipated_boundary\": " << JsonNumber{e.dissipated_boundary}
    << ", \"external_work\": " << JsonNumber{e.external_work}
    << ", \"balance_error\": " << JsonNumber{r.balance_error} << "},\n";
  j << "  \"state_hash\": \"" << r.state_hash << "\"\n";
  j << "}\n";
  return j.str();
}

void RunFiles::write_summary(const RunReport& report, const Model& model,
                             const std::string& scene_name) {
  if (rank_ != 0) return;
  write_file_atomically((std::filesystem::path(directory_) / "summary.json").string(),
                        summary_json(report, model, scene_name));
}

}  // namespace fdem
