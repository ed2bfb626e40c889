// Checkpoint and restart of a Simulation (parallel/checkpoint.hpp holds the file format): rows
// keyed by global id, so any rank count can continue any checkpoint; the run scalars make the
// continuation bit-identical.  The file holds gid − gid_offset (the dense row index), so its rows
// and hashes do not depend on the scene's parallel.gid_offset.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "contact/contact_stage.hpp"
#include "core/error.hpp"
#include "core/state_hash.hpp"
#include "drivers/histories.hpp"
#include "drivers/restart_check.hpp"
#include "drivers/simulation.hpp"
#include "fracture/joint_kernels.hpp"
#include "fracture/joint_stage.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_fields.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

// ---------------------------------------------------------------------------------------------
// Checkpoint and restart (parallel/checkpoint.hpp): rows keyed by global id, so any rank count can
// continue any checkpoint; the run scalars make the continuation bit-identical.
// ---------------------------------------------------------------------------------------------
void Simulation::write_checkpoint() {
  CheckpointHeader header;
  header.n_nodes = whole_nodes_;
  header.n_tets = whole_tets_;
  header.n_joints = whole_joints_;
  header.reference_hash = reference_hash_;
  header.doubles = {{"time", time_},
                    {"time_step", dt_},
                    {"critical_time_step", dt_critical_},
                    {"energy_input", energy_input_},
                    {"kinetic_half_step", kinetic_half_step_},
                    {"next_frame_time", next_frame_time_},
                    {"next_energy_time", next_energy_time_},
                    {"next_checkpoint_time", next_checkpoint_time_},
                    {"next_history_time", histories_ ? histories_->next_time() : 0.0},
                    {"joint_friction_through_previous", joint_friction_.through_previous},
                    {"joint_friction_first_before", joint_friction_.first_before},
                    {"joint_friction_started", joint_friction_.started ? 1.0 : 0.0}};
  for (const auto& [name, value] : ledger_.saved_state())
    header.doubles.emplace_back("ledger_" + name, value);
  for (const auto& [key, value] : restart_scene_values(scene_))  // compared on a restart
    header.doubles.emplace_back(restart_scene_prefix + key, value);
  // The state_hash of the state it holds (as summary.json would give it): verified on restart.
  const std::uint64_t hash = distribution_ ? global_state_hash(model_, *comm_)
                                           : state_hash(model_.nodes, model_.gid_offset);
  header.integers = {{"steps", steps_},
                     {"contact_detected", contact_ && contact_->detected() ? 1 : 0},
                     {"kinetic_damping_stop", stop_motion_ ? 1 : 0},
                     {"kinetic_damping_stops", kinetic_damping_stops_},
                     {"contact_detections", contact_ ? contact_->detections() : 0},
                     {"state_hash", static_cast<std::int64_t>(hash)},
                     {"gid_offset", model_.gid_offset}};  // for the record: rows are gid − it

  // Every checkpoint field of the tables (core/fields.hpp) and the stages' records.
  const CheckpointRows rows = owned_checkpoint_rows(model_, travelling_state());
  char name[64];
  std::snprintf(name, sizeof(name), "checkpoint_%08ld.h5", steps_);
  const std::string path = (std::filesystem::path(options_.output_dir) / name).string();
  fdem::write_checkpoint(path, *comm_, header, rows);
  checkpoints_.push_back(path);
  checkpoint_step_ = steps_;
  // Keep the newest two: the one just written and the previous one.
  if (checkpoints_.size() > 2 && comm_->rank() == 0) {
    std::error_code ignored;
    std::filesystem::remove(checkpoints_[checkpoints_.size() - 3], ignored);
  }
}

void Simulation::restore_checkpoint(const std::string& path) {
  if (!comm_) throw InputError(path + ": a restart needs the MPI environment of the fdem command");
  // Only the rows of what this rank holds (parallel/checkpoint.hpp): its owned and ghost nodes,
  // its joints, and the friction pairs of its tets.
  // The file's rows are gid − gid_offset, whatever offset wrote it.
  const GlobalId offset = model_.gid_offset;
  const auto indices = [&](std::vector<GlobalId> gids) {
    for (GlobalId& g : gids) g -= offset;
    return gids;
  };
  CheckpointWanted wanted;
  const NodeArrays& held = model_.nodes;
  wanted.nodes = indices(held.gid);
  std::inplace_merge(wanted.nodes.begin(), wanted.nodes.begin() + held.n_owned, wanted.nodes.end());
  wanted.joints = indices(model_.joints.gid);
  wanted.tets = indices(model_.tets.gid);
  const auto same_scene = [&](const CheckpointHeader& header) {
    if (header.n_nodes != whole_nodes_ || header.n_tets != whole_tets_ ||
        header.n_joints != whole_joints_ || header.reference_hash != reference_hash_)
      throw InputError("checkpoint '" + path + "' was written for a different scene (" +
                       std::to_string(header.n_nodes) + " nodes, " + std::to_string(header.n_tets) +
                       " tetrahedra, " + std::to_string(header.n_joints) +
                       " joints; this scene has " + std::to_string(whole_nodes_) + ", " +
                       std::to_string(whole_tets_) + ", " + std::to_string(whole_joints_) +
                       (header.n_nodes == whole_nodes_ ? ", and other reference positions" : "") +
                       ")");
  };
  // The stages' state as it is, sized for the model; the rows overwrite it.
  TravellingState state = travelling_state();
  const CheckpointRows layout = checkpoint_layout(state.joint_record_bytes);
  const auto [header, rows] = read_checkpoint(path, *comm_, &wanted, same_scene, &layout);
  std::map<std::string, double> doubles, scene_values;
  for (const auto& [name, value] : header.doubles) doubles[name] = value;
  const std::string prefix = restart_scene_prefix;
  for (const auto& [name, value] : header.doubles)
    if (name.rfind(prefix, 0) == 0) scene_values[name.substr(prefix.size())] = value;
  for (const std::string& warning : compare_restart_scene(scene_, scene_values, path))
    if (is_root()) std::fprintf(stderr, "fdem: warning: restart: %s\n", warning.c_str());
  std::map<std::string, std::int64_t> integers;
  for (const auto& [name, value] : header.integers) integers[name] = value;
  // Rows are indices, so another offset continues the same state; said so, since gids in the
  // output change.  (Checkpoints from before the key have none: offset 0.)
  const auto stored_offset = integers.find("gid_offset");
  const GlobalId written_with = stored_offset == integers.end() ? 0 : stored_offset->second;
  if (written_with != offset && is_root())
    std::fprintf(stderr,
                 "fdem: warning: restart: parallel.gid_offset: the checkpoint was written with "
                 "%lld, this run uses %lld: rows are stored by gid − offset, so the state is the "
                 "same and the gids of the output start from the new offset\n",
                 static_cast<long long>(written_with), static_cast<long long>(offset));
  const auto number = [&](const std::string& name) {
    const auto it = doubles.find(name);
    if (it == doubles.end())
      throw InputError("checkpoint '" + path + "' has no run value '" + name + "'");
    return it->second;
  };
  const auto integer = [&](const std::string& name) {
    const auto it = integers.find(name);
    if (it == integers.end())
      throw InputError("checkpoint '" + path + "' has no run value '" + name + "'");
    return it->second;
  };
  // Rows of the entries held here (all of them when this rank holds the whole model).
  store_checkpoint_rows(rows, model_, state);
  // Every node of the model is restored (on N ranks, by the ranks that own them).
  const std::uint64_t restored =
      distribution_ ? global_state_hash(model_, *comm_) : state_hash(model_.nodes, offset);
  if (static_cast<std::uint64_t>(integer("state_hash")) != restored)
    throw InputError("checkpoint corrupt: the restored state has state_hash " +
                     hash_to_hex(restored) + ", the checkpoint '" + path + "' holds " +
                     hash_to_hex(static_cast<std::uint64_t>(integer("state_hash"))));
  if (joints_) joints_->rebind(model_, joint_histories(state.joint_records));
  if (contact_) {
    // A tet's joint state: cracked once one of its joints broke, intact while it has joints.
    std::vector<std::uint8_t> joint_state = contact_->tet_joint_states();
    const JointArrays& joint_rows = model_.joints;
    // A body with a broken joint anywhere (on any rank) has no enclosed tets left out.
    std::vector<std::int32_t> cracked(static_cast<std::size_t>(model_.pieces.bodies()), 0);
    for (LocalIndex j = 0; j < joint_rows.size(); ++j)
      if (joint_rows.broken[j])
        for (int side = 0; side < 2; ++side) {
          const LocalIndex t = joint_rows.tets[2 * j + side];
          joint_state[t] = static_cast<std::uint8_t>(TetJointState::cracked);
          cracked[static_cast<std::size_t>(model_.pieces.body_of(model_.tets.piece[t]))] = 1;
        }
    comm_->max_in_place(cracked);
    for (std::size_t b = 0; b < cracked.size(); ++b)
      if (cracked[b]) contact_->crack_body(static_cast<std::int32_t>(b));
    contact_->rebind(model_, std::move(state.x_at_detection), std::move(joint_state),
                     friction_entries(state.pairs), integer("contact_detected") != 0);
  }
  time_ = number("time");
  steps_ = integer("steps");
  dt_ = number("time_step");
  dt_critical_ = number("critical_time_step");
  energy_input_ = number("energy_input");
  kinetic_half_step_ = number("kinetic_half_step");
  // Checkpoints from before kinetic damping have no stop pending.
  const auto stop = integers.find("kinetic_damping_stop");
  stop_motion_ = stop != integers.end() && stop->second != 0;
  const auto stops = integers.find("kinetic_damping_stops");
  kinetic_damping_stops_ = stops != integers.end() ? stops->second : 0;
  next_frame_time_ = number("next_frame_time");
  next_energy_time_ = number("next_energy_time");
  next_checkpoint_time_ = number("next_checkpoint_time");
  // Rows continue at the uninterrupted run's times (a checkpoint without the value, or of a run
  // without histories, gives 0: the next step takes a row and the rest follow the interval).
  if (histories_ && doubles.count("next_history_time"))
    histories_->set_next_time(doubles["next_history_time"]);
  joint_friction_.through_previous = number("joint_friction_through_previous");
  joint_friction_.first_before = number("joint_friction_first_before");
  joint_friction_.started = number("joint_friction_started") != 0.0;
  ledger_.restore([&](const std::string& name) { return number("ledger_" + name); },
                  [&](const std::string& name, double fallback) {
                    const auto it = doubles.find("ledger_" + name);
                    return it == doubles.end() ? fallback : it->second;
                  });
}

}  // namespace fdem
