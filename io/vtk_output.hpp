// ParaView output: one VTK XML file per frame and a .pvd series file that lists the frames.
//
// One rank: a frame is one .vtu (tets) or .vtp (contact points, crack triangles).
// N ranks (owner computes): every rank calls the parallel writer with the same path stem; rank r
// writes the piece `<stem>_<r>.vtu` (VTK's own piece naming) and rank 0 also writes the summary
// `<stem>.pvtu` that lists all N pieces (.vtp/.pvtp likewise).  A rank with nothing to write still
// writes an empty piece with the same arrays, so the summary is always complete.  Files are
// streamed by io/vtu_stream in the layout VTK's own XML writers use (appended zlib blocks), so
// the engine does not link VTK (its libraries were ~9.5 MB resident in every rank); nothing in io/
// calls MPI.
//
// Atomicity: every file (.vtu, .vtp, piece, .pvtu, .pvtp, .pvd) is written under `<name>.tmp` and
// renamed, so a crash never leaves a torn file under its final name.  Between ranks there is no
// ordering: rank 0's summary may appear before another rank's piece does (a reader that opens the
// frame in that instant sees a missing piece, never a torn one).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/frame_arrays.hpp"  // FrameField
#include "core/model.hpp"

namespace fdem {

// Name of the file that a series lists for frame `stem` ("frames/frames_000003"):
// "<stem>.<extension>" on one rank, "<stem>.p<extension>" (the summary) on more.  extension:
// "vtu" (tets) or "vtp" (points, triangles).
std::string frame_file_name(const std::string& stem, const std::string& extension, int ranks);
// Name of the piece that `rank` writes for frame `stem` on more than one rank:
// "<stem>_<rank>.<extension>" (as VTK's parallel writers name pieces).
std::string frame_piece_name(const std::string& stem, const std::string& extension, int rank);

class SeriesWriter {
 public:
  // directory: output dir; series: file stem ("frames" → frames.pvd + frames/frames_000000.vtu on
  // one rank, frames/frames_000000.pvtu + frames/frames_000000_<r>.vtu on more).  Every rank
  // constructs its writer and adds the same frames; only rank 0 writes the .pvd.
  SeriesWriter(std::string directory, std::string series, int rank = 0, int ranks = 1);
  // Stem of the next frame, relative to the directory ("frames/frames_000003", no extension).
  std::string next_frame_path() const;
  // File the .pvd lists for frame `stem`: frame_file_name(stem, extension, ranks).
  std::string frame_file(const std::string& stem, const std::string& extension) const {
    return frame_file_name(stem, extension, ranks_);
  }
  // Records a dataset at `time` (`relative_path` relative to the directory, as frame_file gives)
  // and, on rank 0, rewrites the .pvd.
  void add_frame(double time, const std::string& relative_path);
  std::size_t frames() const { return entries_.size(); }
  int rank() const { return rank_; }
  int ranks() const { return ranks_; }

 private:
  void write_pvd() const;
  std::string directory_, series_;
  int rank_ = 0, ranks_ = 1;
  std::vector<std::pair<double, std::string>> entries_;
};

// Writes the tets of `model` that this rank owns (TetArrays::is_owned; all of them on one rank)
// and the nodes they reference, renumbered in local node order, to the .vtu `path`.  Arrays:
// point data gid (node global id), displacement / velocity (if in `fields`), per-point `extra`;
// cell data gid (tet global id), piece, body, material, stress (Cauchy, 9) and von_mises (if
// "stress" is in `fields`), per-cell `extra`.
void write_tet_frame(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields, const std::vector<FrameField>& extra);

// Parallel tet frame: called by every rank with the same `stem` (absolute, without extension).
// ranks > 1: writes piece frame_piece_name(stem, "vtu", rank) with this rank's owned tets, and on
// rank 0 the summary frame_file_name(stem, "vtu", ranks) listing all `ranks` pieces.  ranks == 1:
// write_tet_frame(stem + ".vtu", ...).  Every rank must pass the same `fields` and the same `extra`
// names and components.
void write_parallel_tet_frame(const std::string& stem, const Model& model,
                              const std::vector<std::string>& fields,
                              const std::vector<FrameField>& extra, int rank, int ranks);

// Writes points (3 doubles each) with per-point arrays as a .vtp (VTK poly data, one vertex per
// point).
void write_point_frame(const std::string& path, const std::vector<double>& points,
                       const std::vector<FrameField>& point_fields);
// Parallel point frame: this rank's points as piece `rank` of `stem` (.vtp pieces, .pvtp summary on
// rank 0); ranks == 1: write_point_frame(stem + ".vtp", ...).
void write_parallel_point_frame(const std::string& stem, const std::vector<double>& points,
                                const std::vector<FrameField>& point_fields, int rank, int ranks);

// Writes triangles (3 point indices each into `points`, 3 doubles per point) with per-triangle
// arrays as a .vtp (VTK poly data).
void write_triangle_frame(const std::string& path, const std::vector<double>& points,
                          const std::vector<std::int64_t>& triangles,
                          const std::vector<FrameField>& cell_fields);
// Parallel triangle frame: this rank's triangles as piece `rank` of `stem` (.vtp pieces, .pvtp
// summary on rank 0); ranks == 1: write_triangle_frame(stem + ".vtp", ...).
void write_parallel_triangle_frame(const std::string& stem, const std::vector<double>& points,
                                   const std::vector<std::int64_t>& triangles,
                                   const std::vector<FrameField>& cell_fields, int rank, int ranks);

// Atomically replaces `path` with `content`.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace fdem
