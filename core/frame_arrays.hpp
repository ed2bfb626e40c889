// The arrays of a tet frame as plain data, computed once from the model for every frame writer:
// the .vtu pieces (io/vtk_output) and the collective HDF5 frames (parallel/xdmf_output, listed in
// an .xdmf series by io/xdmf_series).  Nothing here knows a file format or MPI.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/model.hpp"

namespace fdem {

// Extra per-cell or per-point arrays that stages contribute to a frame.  Tet frames: given per
// local tet (per_cell) or per local node of the Model; the writer keeps the entries of the tets it
// writes and of the nodes those reference.  Point/triangle frames: per written point/triangle.
struct FrameField {
  std::string name;
  int components = 1;
  bool per_cell = true;
  std::vector<double> values;  // components × (cells or points)
};

// Value type of a frame array (and of its dataset in a file).
enum class FrameValue { f64, i32, i64 };

// One array of a frame: `components` values per written cell (per_cell) or per written point.
struct FrameArray {
  std::string name;
  bool per_cell = true;
  int components = 1;
  FrameValue type = FrameValue::f64;
  std::vector<double> real;           // f64 values
  std::vector<std::int64_t> integer;  // i32 / i64 values (i32 ones fit 32 bits)

  std::size_t values() const { return type == FrameValue::f64 ? real.size() : integer.size(); }
};

// One array of a frame produced on demand, a range of rows at a time: a writer that streams it
// in blocks holds neither the frame nor the whole array.  `fill_real` (f64) or `fill_integer`
// (i32, i64) writes the components × count values of rows [first, first + count) to `out`.
struct FrameColumn {
  std::string name;
  bool per_cell = true;
  int components = 1;
  FrameValue type = FrameValue::f64;
  std::size_t rows = 0;
  std::function<void(std::size_t first, std::size_t count, double* out)> fill_real;
  std::function<void(std::size_t first, std::size_t count, std::int64_t* out)> fill_integer;

  // The whole column as one array (for writers that take whole arrays).
  FrameArray materialize() const;
};

// The local tets or nodes a frame writes, ascending: the entries of a list, which must outlive the
// selection, or all of 0 … n−1 (a rank that writes every local tet and node builds no list).
class LocalSelection {
 public:
  LocalSelection() = default;                          // none
  LocalSelection(const std::vector<LocalIndex>& list)  // NOLINT(google-explicit-constructor)
      : list_(&list), size_(list.size()) {}
  static LocalSelection first(std::size_t n) {
    LocalSelection all;
    all.size_ = n;
    return all;
  }
  std::size_t size() const { return size_; }
  LocalIndex operator[](std::size_t i) const {
    return list_ ? (*list_)[i] : static_cast<LocalIndex>(i);
  }

 private:
  const std::vector<LocalIndex>* list_ = nullptr;
  std::size_t size_ = 0;
};

// Local tets this rank writes in a frame: the owned ones (TetArrays::is_owned), ascending, so in
// ascending gid (all of them on one rank).
std::vector<LocalIndex> owned_tets(const TetArrays& tets);

// Cauchy stress (Pa) of local tet t at the current positions, from its elastic law (no viscous
// part); zero for an inverted tet (J <= 0).  Frames and history monitors show this stress.
Mat3 elastic_cauchy_stress(const Model& model, LocalIndex t);

// The arrays of a tet frame for the local tets `cells` and the local nodes `points`, in this
// order: point data gid (i64), displacement (x − x0, m) and velocity (m/s) if in `fields`; cell
// data gid (i64), piece, body, material (i32), stress (Cauchy, Pa, 9 row-major) and von_mises
// (Pa) if "stress" is in `fields`; then the `extra` fields (filtered to cells / points).
std::vector<FrameArray> tet_frame_arrays(const Model& model, LocalSelection cells,
                                         LocalSelection points,
                                         const std::vector<std::string>& fields,
                                         const std::vector<FrameField>& extra);
// The same arrays as columns, in the same order, computed when a writer asks for their rows;
// they read `model`, the selections' lists and `extra`, which must outlive them.
std::vector<FrameColumn> tet_frame_columns(const Model& model, LocalSelection cells,
                                           LocalSelection points,
                                           const std::vector<std::string>& fields,
                                           const std::vector<FrameField>& extra);

// A dataset of a written frame file: what the series file (.xdmf) needs to reference it.
struct FrameDataset {
  enum class Role { geometry, topology, point, cell } role = Role::point;
  std::string name;  // array name shown in ParaView ("" for geometry and topology)
  std::string path;  // inside the file, e.g. "/tets/stress"
  std::int64_t rows = 0;
  int components = 1;  // values per row (dataset shape rows × components; 1: one-dimensional)
  FrameValue type = FrameValue::f64;
};

// One written frame: the file (relative to the series file), its time and datasets.
struct FrameFileInfo {
  std::string file;
  double time = 0.0;  // s
  std::int64_t n_nodes = 0, n_tets = 0;
  std::vector<FrameDataset> datasets;
};

}  // namespace fdem
