// The files of an output directory: energy.csv, bodies.csv, frames.pvd (+ frames/*.vtu) or
// frames.xdmf (+ frames/*.h5), and summary.json.  CSV rows are flushed as they are written so a
// failed run keeps its history.
#pragma once

#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/dynamics.hpp"
#include "core/energy.hpp"
#include "core/model.hpp"
#include "io/vtk_output.hpp"
#include "io/xdmf_series.hpp"
#include "parallel/ordered_text_file.hpp"
#include "parallel/xdmf_output.hpp"

namespace fdem {

class JointStage;

struct RunReport;
struct StagePlan;

// Tet frames as one HDF5 file per frame written collectively over `comm` (nullptr: this process
// alone), listed in frames.xdmf (parallel/xdmf_output, io/xdmf_series), instead of .vtu pieces.
struct XdmfFrames {
  const Communicator* comm = nullptr;
  MpiIoHints hints;  // MPI-IO hints (scene output.mpi_io_hints + FDEM_MPIIO_HINTS)
};

class RunFiles {
 public:
  // On N ranks every rank makes one (frames are written in pieces by every rank); the CSV and
  // JSON files are written by rank 0 alone.
  // With `xdmf`, tet frames go to frames.xdmf + frames/frames_<n>.h5 (collective: every rank
  // calls write_frame); else to frames.pvd + .vtu / .pvtu pieces.
  RunFiles(const std::string& directory, const std::vector<std::string>& fields, int rank = 0,
           int ranks = 1, std::optional<XdmfFrames> xdmf = std::nullopt);
  void write_energy_row(double time, const EnergyTerms& e, double balance_error);
  // One process: the bodies.csv rows of every piece (motion indexed by piece id).
  void write_bodies_rows(double time, const Model& model, const std::vector<PieceMotion>& motion);
  // N ranks, collective: every rank's rows of the pieces first_piece, first_piece + 1, ... (its
  // directory block, parallel/piece_directory) go into bodies.csv in piece order (MPI-IO).
  void write_bodies_rows(double time, const Model& model, std::int32_t first_piece,
                         const std::vector<PieceMotion>& motion, const Communicator& comm);
  // A frame of the tets; with `damage` in the fields, the per-tet damage; in a model with joints
  // also a frame of the "cracks" series (broken joint faces).
  // `joints`: the joint stage when the scene has joints (on every rank then: each writes a
  // piece), else null.
  // `node_owner`: per local node its owning rank (Distribution::node_owners), read by xdmf frames
  // on N ranks for the ghost nodes of owned tets; empty on one rank.
  void write_frame(double time, const Model& model, const std::vector<FrameField>& extra = {},
                   const JointStage* joints = nullptr,
                   const std::vector<std::int32_t>& node_owner = {});
  // Broken joint faces as triangles (face A's current position) with mode (FailureMode code),
  // failure_time (s) and opening (mean gap |b_i − a_i|, m), as the "cracks" series.
  void write_cracks(double time, const Model& model, const JointStage& joints);
  // Contact points with their normal and tangential forces, as the "contacts" series.
  void write_contacts(double time, const std::vector<ContactRecord>& records);
  void write_summary(const RunReport& report, const Model& model, const std::string& scene_name);
  const std::string& directory() const { return directory_; }

 private:
  void write_xdmf_tet_frame(double time, const Model& model, const std::vector<FrameField>& extra,
                            const std::vector<std::int32_t>& node_owner);
  std::string directory_;
  std::vector<std::string> fields_;
  int rank_ = 0, ranks_ = 1;
  std::ofstream energy_, bodies_;                   // bodies_: one process only
  std::unique_ptr<OrderedTextFile> shared_bodies_;  // N ranks
  SeriesWriter frames_;
  std::optional<XdmfFrames> xdmf_;
  std::unique_ptr<XdmfSeries> xdmf_series_;
  std::unique_ptr<SeriesWriter> contacts_, cracks_;
};

// The bodies.csv rows of pieces first_piece, first_piece + 1, ... at `time` (the same text on any
// number of ranks).
std::string bodies_rows(double time, const Model& model, std::int32_t first_piece,
                        const std::vector<PieceMotion>& motion);

// Per-tet damage: the largest damage of the tet's joints (0 for a tet without joints; all 0
// without a joint stage).
std::vector<double> tet_damage(const Model& model, const JointStage* joints);

// JSON text of the run summary (also used by `fdem check --json` and tests).
std::string summary_json(const RunReport& report, const Model& model,
                         const std::string& scene_name);

}  // namespace fdem
