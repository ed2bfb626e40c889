// The .xdmf series file of the collective HDF5 frames (parallel/xdmf_output): XDMF 3 XML, one
// Temporal Collection with one Uniform grid per frame whose topology, geometry and attributes
// reference the datasets of that frame's HDF5 file ("frames/frames_000003.h5:/nodes/xyz").
// ParaView opens the .xdmf directly (its XDMF 3 reader; the XDMF 2 one reads the same file).
//
// The file is rewritten by one rank (rank 0) after every frame, atomically (under `.tmp`, then
// renamed), so a run killed at any point leaves a readable series of its complete frames.
// Nothing here calls MPI.
#pragma once

#include <string>
#include <vector>

#include "core/frame_arrays.hpp"

namespace fdem {

// XML text of a series of frames (file names relative to the series file's directory).
std::string xdmf_series_xml(const std::string& series, const std::vector<FrameFileInfo>& frames);

class XdmfSeries {
 public:
  // directory: output dir; series: file stem ("frames" → frames.xdmf + frames/frames_000000.h5).
  // Every rank constructs one and adds the same frames; only `writer` rewrites the .xdmf.
  XdmfSeries(std::string directory, std::string series, bool writer);
  // The next frame's HDF5 file relative to the directory ("frames/frames_000003.h5").
  std::string next_frame_file() const;
  // Records a written frame and, on the writing rank, rewrites the .xdmf.
  void add_frame(FrameFileInfo frame);
  std::size_t frames() const { return frames_.size(); }
  std::string path() const;  // the .xdmf file

 private:
  std::string directory_, series_;
  bool writer_ = false;
  std::vector<FrameFileInfo> frames_;
};

}  // namespace fdem
