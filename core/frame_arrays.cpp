#include "core/frame_arrays.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

// A column of `n` rows whose row r is value_of(r) (components values written to out).
template <class ValueOf>
FrameColumn real_column(const std::string& name, bool per_cell, int components, std::size_t n,
                        ValueOf value_of) {
  FrameColumn c{name, per_cell, components, FrameValue::f64, n, {}, {}};
  c.fill_real = [value_of, components](std::size_t first, std::size_t count, double* out) {
    for (std::size_t r = 0; r < count; ++r) value_of(first + r, out + r * components);
  };
  return c;
}

template <class ValueOf>
FrameColumn integer_column(const std::string& name, bool per_cell, FrameValue type, std::size_t n,
                           ValueOf value_of) {
  FrameColumn c{name, per_cell, 1, type, n, {}, {}};
  c.fill_integer = [value_of](std::size_t first, std::size_t count, std::int64_t* out) {
    for (std::size_t r = 0; r < count; ++r) out[r] = value_of(first + r);
  };
  return c;
}

// The entries `kept` of a field given for all `all_entries` local tets or nodes.
FrameColumn filtered(const FrameField& f, std::size_t all_entries, LocalSelection kept) {
  FDEM_VERIFY(f.values.size() == all_entries * static_cast<std::size_t>(f.components),
              "frame field size");
  const int n = f.components;
  return real_column(f.name, f.per_cell, n, kept.size(), [&f, kept, n](std::size_t r, double* out) {
    for (int c = 0; c < n; ++c) out[c] = f.values[static_cast<std::size_t>(kept[r]) * n + c];
  });
}

}  // namespace

Mat3 elastic_cauchy_stress(const Model& model, LocalIndex t) {
  const TetArrays& tets = model.tets;
  Vec3 x[4];
  for (int k = 0; k < 4; ++k) x[k] = vec3_at(model.nodes.x.data(), tets.nodes[4 * t + k]);
  const Mat3 F = edge_matrix(x) * Eigen::Map<const Mat3>(tets.dm_inv.data() + 9 * t);
  const double J = F.determinant();
  if (!(J > 0.0)) return Mat3::Zero();
  const MaterialProperties& mat = model.materials[tets.material[t]];
  const Mat3 P = mat.model == ElasticModel::neo_hookean
                     ? NeoHookean{mat.lame}.first_piola(F)
                     : StVenantKirchhoff{mat.lame}.first_piola(F);
  return P * F.transpose() / J;
}

std::vector<LocalIndex> owned_tets(const TetArrays& tets) {
  std::vector<LocalIndex> cells;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    if (tets.is_owned(t)) cells.push_back(t);
  return cells;
}

FrameArray FrameColumn::materialize() const {
  FrameArray a{name, per_cell, components, type, {}, {}};
  const std::size_t values = rows * static_cast<std::size_t>(components);
  if (type == FrameValue::f64) {
    a.real.resize(values);
    fill_real(0, rows, a.real.data());
  } else {
    a.integer.resize(values);
    fill_integer(0, rows, a.integer.data());
  }
  return a;
}

std::vector<FrameColumn> tet_frame_columns(const Model& model, LocalSelection cells,
                                           LocalSelection points,
                                           const std::vector<std::string>& fields,
                                           const std::vector<FrameField>& extra) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  const auto wants = [&](const char* f) {
    return std::find(fields.begin(), fields.end(), f) != fields.end();
  };
  const std::size_t n_points = points.size(), n_cells = cells.size();
  std::vector<FrameColumn> columns;

  columns.push_back(
      integer_column("gid", false, FrameValue::i64, n_points,
                     [&nodes, points](std::size_t p) { return nodes.gid[points[p]]; }));
  if (wants("displacement"))
    columns.push_back(
        real_column("displacement", false, 3, n_points, [&nodes, points](std::size_t p, double* u) {
          for (int k = 0; k < 3; ++k) u[k] = nodes.x[3 * points[p] + k] - nodes.x0(points[p])[k];
        }));
  if (wants("velocity"))
    columns.push_back(
        real_column("velocity", false, 3, n_points, [&nodes, points](std::size_t p, double* v) {
          for (int k = 0; k < 3; ++k) v[k] = nodes.v[3 * points[p] + k];
        }));

  const auto cell_integers = [&](const char* name, FrameValue type, auto value_of) {
    columns.push_back(integer_column(name, true, type, n_cells, [cells, value_of](std::size_t c) {
      return value_of(cells[c]);
    }));
  };
  cell_integers("gid", FrameValue::i64, [&tets](LocalIndex t) { return tets.gid[t]; });
  cell_integers("piece", FrameValue::i32, [&tets](LocalIndex t) { return tets.piece[t]; });
  cell_integers("body", FrameValue::i32,
                [&model](LocalIndex t) { return model.pieces.body_of(model.tets.piece[t]); });
  cell_integers("material", FrameValue::i32, [&tets](LocalIndex t) { return tets.material[t]; });

  if (wants("stress")) {
    columns.push_back(
        real_column("stress", true, 9, n_cells, [&model, cells](std::size_t c, double* sigma) {
          const Mat3 cauchy = elastic_cauchy_stress(model, cells[c]);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) sigma[3 * i + j] = cauchy(i, j);
        }));
    columns.push_back(
        real_column("von_mises", true, 1, n_cells, [&model, cells](std::size_t c, double* mises) {
          const Mat3 cauchy = elastic_cauchy_stress(model, cells[c]);
          const Mat3 dev = cauchy - cauchy.trace() / 3.0 * Mat3::Identity();
          *mises = std::sqrt(1.5 * dev.squaredNorm());
        }));
  }
  for (const FrameField& f : extra)
    columns.push_back(f.per_cell ? filtered(f, static_cast<std::size_t>(tets.size()), cells)
                                 : filtered(f, static_cast<std::size_t>(nodes.size()), points));
  return columns;
}

std::vector<FrameArray> tet_frame_arrays(const Model& model, LocalSelection cells,
                                         LocalSelection points,
                                         const std::vector<std::string>& fields,
                                         const std::vector<FrameField>& extra) {
  std::vector<FrameArray> arrays;
  for (const FrameColumn& column : tet_frame_columns(model, cells, points, fields, extra))
    arrays.push_back(column.materialize());
  return arrays;
}

}  // namespace fdem
