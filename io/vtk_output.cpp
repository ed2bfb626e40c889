#include "io/vtk_output.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"
#include "io/vtu_stream.hpp"

namespace fdem {

namespace {

// Removes a partial file, keeping errno (the reason the write failed) for the message.
void remove_partial(const std::string& path) {
  const int saved = errno;
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  errno = saved;
}

std::string system_reason() {
  return errno != 0 ? std::strerror(errno) : "disk full or no permission?";
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  errno = 0;
  std::ofstream out(tmp, std::ios::binary);
  out << content;
  out.close();  // the last bytes reach the disk here: check after closing
  if (!out) {
    const std::string reason = system_reason();
    remove_partial(tmp);
    throw IoError("cannot write " + path + ": " + reason);
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    remove_partial(tmp);
    throw IoError("cannot rename " + tmp + " to " + path + ": " + error.message());
  }
}

std::string frame_file_name(const std::string& stem, const std::string& extension, int ranks) {
  return stem + (ranks > 1 ? ".p" : ".") + extension;
}

std::string frame_piece_name(const std::string& stem, const std::string& extension, int rank) {
  return stem + "_" + std::to_string(rank) + "." + extension;
}

SeriesWriter::SeriesWriter(std::string directory, std::string series, int rank, int ranks)
    : directory_(std::move(directory)), series_(std::move(series)), rank_(rank), ranks_(ranks) {
  FDEM_VERIFY(ranks_ >= 1 && rank_ >= 0 && rank_ < ranks_, "series writer rank");
  std::filesystem::create_directories(std::filesystem::path(directory_) / series_);
}

std::string SeriesWriter::next_frame_path() const {
  std::ostringstream name;
  name << series_ << "/" << series_ << "_" << std::setw(6) << std::setfill('0') << entries_.size();
  return name.str();
}

void SeriesWriter::add_frame(double time, const std::string& relative_path) {
  entries_.emplace_back(time, relative_path);
  if (rank_ == 0) write_pvd();
}

void SeriesWriter::write_pvd() const {
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  xml << std::setprecision(17);
  for (const auto& [time, file] : entries_)
    xml << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file
        << "\"/>\n";
  xml << "  </Collection>\n</VTKFile>\n";
  write_file_atomically((std::filesystem::path(directory_) / (series_ + ".pvd")).string(),
                        xml.str());
}

namespace {

// zlib level of the frames' arrays: 1 is the fastest.  Measured on the jointed bricks (11,520
// tets, two frames): the output stage took a third of its time at zlib's default level (6),
// 0.47 → 0.155 s, for frames 10–25 % larger (1.51 → 1.66 MB).
constexpr int frame_compression_level = 1;

// A frame column as a streamed .vtu array: f64 → Float64, i64 → Int64, i32 → Int32.
VtuArray vtu_array(const FrameColumn& c) {
  const char* type = c.type == FrameValue::f64   ? "Float64"
                     : c.type == FrameValue::i64 ? "Int64"
                                                 : "Int32";
  VtuArray a{c.name, type, c.components, c.rows, {}};
  const std::size_t n = static_cast<std::size_t>(c.components);
  a.fill = [&c, n](std::size_t first, std::size_t count, unsigned char* out) {
    if (c.type == FrameValue::f64) {
      std::vector<double> values(count * n);
      c.fill_real(first, count, values.data());
      std::memcpy(out, values.data(), values.size() * sizeof(double));
      return;
    }
    std::vector<std::int64_t> values(count * n);
    c.fill_integer(first, count, values.data());
    if (c.type == FrameValue::i64) {
      std::memcpy(out, values.data(), values.size() * sizeof(std::int64_t));
      return;
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      const auto value = static_cast<std::int32_t>(values[i]);
      std::memcpy(out + 4 * i, &value, 4);
    }
  };
  return a;
}

// The owned tets of `model` and the nodes they reference, renumbered in ascending local order,
// as a streamed .vtu grid.  On one rank, where every tet is owned and every node in a tet, that
// is the identity and no index list is built (they were ~40 B per tet at a frame, the run's peak
// of a large jointed body).  The grid's arrays read the model and this object, which is neither
// copied nor moved.
class OwnedTetGrid {
 public:
  OwnedTetGrid(const Model& model, const std::vector<std::string>& fields,
               const std::vector<FrameField>& extra) {
    const NodeArrays& nodes = model.nodes;
    const TetArrays& tets = model.tets;
    const auto n_nodes = static_cast<std::size_t>(nodes.size());
    std::size_t owned = 0;
    std::vector<bool> used(n_nodes, false);
    for (LocalIndex t = 0; t < tets.size(); ++t)
      if (tets.is_owned(t)) {
        ++owned;
        for (int c = 0; c < 4; ++c) used[static_cast<std::size_t>(tets.nodes[4 * t + c])] = true;
      }
    const auto n_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
    identity_ = owned == static_cast<std::size_t>(tets.size()) && n_used == n_nodes;
    if (!identity_) {
      cells_ = owned_tets(tets);
      renumbered_.assign(n_nodes, -1);
      points_.reserve(n_used);
      for (std::size_t i = 0; i < n_nodes; ++i)
        if (used[i]) {
          renumbered_[i] = static_cast<LocalIndex>(points_.size());
          points_.push_back(static_cast<LocalIndex>(i));
        }
    }
    const LocalSelection cells = identity_ ? LocalSelection::first(owned) : cells_;
    const LocalSelection points = identity_ ? LocalSelection::first(n_nodes) : points_;
    columns_ = tet_frame_columns(model, cells, points, fields, extra);
    grid_.points = points.size();
    grid_.cells = cells.size();
    for (const FrameColumn& c : columns_)
      (c.per_cell ? grid_.cell_data : grid_.point_data).push_back(vtu_array(c));
    grid_.positions = {"Points", "Float64", 3, points.size(),
                       [&nodes, points](std::size_t first, std::size_t count, unsigned char* out) {
                         for (std::size_t p = 0; p < count; ++p)
                           std::memcpy(out + 24 * p, &nodes.x[3 * points[first + p]], 24);
                       }};
    grid_.corners = {
        "connectivity", "Int64", 4, cells.size(),
        [this, &tets, cells](std::size_t first, std::size_t count, unsigned char* out) {
          for (std::size_t c = 0; c < count; ++c)
            for (int k = 0; k < 4; ++k) {
              const LocalIndex n = tets.nodes[4 * cells[first + c] + k];
              const auto point = static_cast<std::int64_t>(identity_ ? n : renumbered_[n]);
              std::memcpy(out + 32 * c + 8 * k, &point, 8);
            }
        }};
  }
  OwnedTetGrid(const OwnedTetGrid&) = delete;
  OwnedTetGrid& operator=(const OwnedTetGrid&) = delete;
  const VtuGrid& grid() const { return grid_; }

 private:
  bool identity_ = false;  // every local tet and node written, in local order
  std::vector<LocalIndex> cells_, renumbered_, points_;  // points: local nodes written, ascending
  std::vector<FrameColumn> columns_;
  VtuGrid grid_;
};

// A per-point or per-cell field as a streamed array (Float64), its size checked.
VtuArray field_array(const FrameField& f, std::size_t tuples, const char* what) {
  FDEM_VERIFY(f.values.size() == tuples * static_cast<std::size_t>(f.components), what);
  const std::size_t n = static_cast<std::size_t>(f.components);
  return {f.name, "Float64", f.components, tuples,
          [&f, n](std::size_t first, std::size_t count, unsigned char* out) {
            std::memcpy(out, f.values.data() + first * n, count * n * sizeof(double));
          }};
}

VtuArray position_array(const std::vector<double>& points) {
  return {"Points", "Float64", 3, points.size() / 3,
          [&points](std::size_t first, std::size_t count, unsigned char* out) {
            std::memcpy(out, points.data() + 3 * first, 24 * count);
          }};
}

// Contact points: one vertex cell per point.  The arrays read the caller's vectors.
VtpPolys point_polys(const std::vector<double>& points,
                     const std::vector<FrameField>& point_fields) {
  VtpPolys polys;
  polys.kind = VtpPolys::Cells::vertices;
  polys.points = polys.cells = points.size() / 3;
  polys.positions = position_array(points);
  polys.corners = {"connectivity", "Int64", 1, polys.cells,
                   [](std::size_t first, std::size_t count, unsigned char* out) {
                     for (std::size_t c = 0; c < count; ++c) {
                       const auto point = static_cast<std::int64_t>(first + c);
                       std::memcpy(out + 8 * c, &point, 8);
                     }
                   }};
  for (const FrameField& f : point_fields)
    polys.point_data.push_back(field_array(f, polys.points, "point field size"));
  return polys;
}

// Crack triangles: corners index `points`.
VtpPolys triangle_polys(const std::vector<double>& points,
                        const std::vector<std::int64_t>& triangles,
                        const std::vector<FrameField>& cell_fields) {
  VtpPolys polys;
  polys.kind = VtpPolys::Cells::triangles;
  polys.points = points.size() / 3;
  polys.cells = triangles.size() / 3;
  polys.positions = position_array(points);
  polys.corners = {"connectivity", "Int64", 3, polys.cells,
                   [&triangles](std::size_t first, std::size_t count, unsigned char* out) {
                     std::memcpy(out, triangles.data() + 3 * first, 24 * count);
                   }};
  for (const FrameField& f : cell_fields)
    polys.cell_data.push_back(field_array(f, polys.cells, "triangle field size"));
  return polys;
}

// `tmp` renamed to `path` (removed if that fails).
void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    remove_partial(tmp);
    throw IoError("cannot rename " + tmp + " to " + path + ": " + error.message());
  }
}

void write_serial_polys(const std::string& path, const VtpPolys& polys) {
  const std::string tmp = path + ".tmp";
  write_vtp(tmp, polys, frame_compression_level, "cannot write the frame " + path);
  rename_into_place(tmp, path);
}

// Piece `rank` of `ranks` of frame `stem` (written even when empty, with the same arrays, so
// every piece the summary lists exists) through `write(path, what)`; rank 0 also writes the
// summary that `summary(piece file names)` makes.
void write_piece_and_summary(
    const std::string& stem, const char* extension, int rank, int ranks,
    const std::function<void(const std::string&, const std::string&)>& write,
    const std::function<std::string(const std::vector<std::string>&)>& summary) {
  const std::string piece = frame_piece_name(stem, extension, rank);
  write(piece + ".tmp", "cannot write the frame piece " + piece);
  rename_into_place(piece + ".tmp", piece);
  if (rank != 0) return;
  std::vector<std::string> pieces;
  for (int r = 0; r < ranks; ++r)
    pieces.push_back(
        std::filesystem::path(frame_piece_name(stem, extension, r)).filename().string());
  write_file_atomically(frame_file_name(stem, extension, ranks), summary(pieces));
}

void write_polys_piece(const std::string& stem, const VtpPolys& polys, int rank, int ranks) {
  write_piece_and_summary(
      stem, "vtp", rank, ranks,
      [&](const std::string& path, const std::string& what) {
        write_vtp(path, polys, frame_compression_level, what);
      },
      [&](const std::vector<std::string>& pieces) { return pvtp_summary(polys, pieces); });
}

// Checks the rank numbers; true on one rank (a plain .vtu/.vtp, no pieces).
bool single_rank(int rank, int ranks) {
  FDEM_VERIFY(ranks >= 1 && rank >= 0 && rank < ranks, "frame rank");
  return ranks == 1;
}

}  // namespace

void write_tet_frame(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields, const std::vector<FrameField>& extra) {
  const OwnedTetGrid owned(model, fields, extra);
  const std::string tmp = path + ".tmp";
  write_vtu(tmp, owned.grid(), frame_compression_level, "cannot write the frame " + path);
  rename_into_place(tmp, path);
}

void write_parallel_tet_frame(const std::string& stem, const Model& model,
                              const std::vector<std::string>& fields,
                              const std::vector<FrameField>& extra, int rank, int ranks) {
  if (single_rank(rank, ranks))
    return write_tet_frame(frame_file_name(stem, "vtu", 1), model, fields, extra);
  const OwnedTetGrid owned(model, fields, extra);
  write_piece_and_summary(
      stem, "vtu", rank, ranks,
      [&](const std::string& path, const std::string& what) {
        write_vtu(path, owned.grid(), frame_compression_level, what);
      },
      [&](const std::vector<std::string>& pieces) { return pvtu_summary(owned.grid(), pieces); });
}

void write_point_frame(const std::string& path, const std::vector<double>& points,
                       const std::vector<FrameField>& point_fields) {
  write_serial_polys(path, point_polys(points, point_fields));
}

void write_parallel_point_frame(const std::string& stem, const std::vector<double>& points,
                                const std::vector<FrameField>& point_fields, int rank, int ranks) {
  if (single_rank(rank, ranks))
    return write_point_frame(frame_file_name(stem, "vtp", 1), points, point_fields);
  write_polys_piece(stem, point_polys(points, point_fields), rank, ranks);
}

void write_triangle_frame(const std::string& path, const std::vector<double>& points,
                          const std::vector<std::int64_t>& triangles,
                          const std::vector<FrameField>& cell_fields) {
  write_serial_polys(path, triangle_polys(points, triangles, cell_fields));
}

void write_parallel_triangle_frame(const std::string& stem, const std::vector<double>& points,
                                   const std::vector<std::int64_t>& triangles,
                                   const std::vector<FrameField>& cell_fields, int rank,
                                   int ranks) {
  if (single_rank(rank, ranks))
    return write_triangle_frame(frame_file_name(stem, "vtp", 1), points, triangles, cell_fields);
  write_polys_piece(stem, triangle_polys(points, triangles, cell_fields), rank, ranks);
}

}  // namespace fdem
