// ParaView output: one .vtu per frame (written with VTK's XML writer) and a .pvd series file.
// Each file is written under a temporary name and renamed, so a crash never leaves a torn frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/model.hpp"

namespace fdem {

// Extra per-cell or per-point arrays that stages contribute to a frame.
struct FrameField {
  std::string name;
  int components = 1;
  bool per_cell = true;
  std::vector<double> values;  // components × (cells or points)
};

class SeriesWriter {
 public:
  // directory: output dir; series: file stem ("frames" → frames.pvd + frames/frames_000000.vtu).
  SeriesWriter(std::string directory, std::string series);
  // Adds a dataset at `time` and rewrites the .pvd.  `path` is the piece written by the caller.
  std::string next_frame_path();
  void add_frame(double time, const std::string& relative_path);
  std::size_t frames() const { return entries_.size(); }

 private:
  void write_pvd() const;
  std::string directory_, series_;
  std::vector<std::pair<double, std::string>> entries_;
};

// Writes the tets of `model` with the requested fields (displacement, velocity, stress, ...).
void write_tet_frame(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields, const std::vector<FrameField>& extra);

// Writes points (3 doubles each) with per-point arrays as a .vtp (VTK poly data, one vertex per
// point).
void write_point_frame(const std::string& path, const std::vector<double>& points,
                       const std::vector<FrameField>& point_fields);

// Writes triangles (3 point indices each into `points`, 3 doubles per point) with per-triangle
// arrays as a .vtp (VTK poly data).
void write_triangle_frame(const std::string& path, const std::vector<double>& points,
                          const std::vector<std::int64_t>& triangles,
                          const std::vector<FrameField>& cell_fields);

// Atomically replaces `path` with `content`.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace fdem
