#include "core/frame_arrays.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

FrameArray real_array(const std::string& name, bool per_cell, int components, std::size_t n) {
  FrameArray a{name, per_cell, components, FrameValue::f64, {}, {}};
  a.real.resize(n * static_cast<std::size_t>(components));
  return a;
}

FrameArray integer_array(const std::string& name, bool per_cell, FrameValue type, std::size_t n) {
  FrameArray a{name, per_cell, 1, type, {}, {}};
  a.integer.resize(n);
  return a;
}

// The entries `kept` of a field given for all `all_entries` local tets or nodes.
FrameArray filtered(const FrameField& f, std::size_t all_entries,
                    const std::vector<LocalIndex>& kept) {
  FDEM_VERIFY(f.values.size() == all_entries * static_cast<std::size_t>(f.components),
              "frame field size");
  FrameArray a = real_array(f.name, f.per_cell, f.components, kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i)
    for (int c = 0; c < f.components; ++c)
      a.real[i * f.components + c] = f.values[static_cast<std::size_t>(kept[i]) * f.components + c];
  return a;
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

void for_each_tet_frame_array(const Model& model, const std::vector<LocalIndex>& cells,
                              const std::vector<LocalIndex>& points,
                              const std::vector<std::string>& fields,
                              const std::vector<FrameField>& extra,
                              const std::function<void(FrameArray&)>& take) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  const auto wants = [&](const char* f) {
    return std::find(fields.begin(), fields.end(), f) != fields.end();
  };
  const std::size_t n_points = points.size(), n_cells = cells.size();

  FrameArray node_gid = integer_array("gid", false, FrameValue::i64, n_points);
  for (std::size_t p = 0; p < n_points; ++p) node_gid.integer[p] = nodes.gid[points[p]];
  take(node_gid);
  if (wants("displacement")) {
    FrameArray u = real_array("displacement", false, 3, n_points);
    for (std::size_t p = 0; p < n_points; ++p)
      for (int k = 0; k < 3; ++k)
        u.real[3 * p + k] = nodes.x[3 * points[p] + k] - nodes.x0[3 * points[p] + k];
    take(u);
  }
  if (wants("velocity")) {
    FrameArray v = real_array("velocity", false, 3, n_points);
    for (std::size_t p = 0; p < n_points; ++p)
      for (int k = 0; k < 3; ++k) v.real[3 * p + k] = nodes.v[3 * points[p] + k];
    take(v);
  }

  const auto cell_integers = [&](const char* name, FrameValue type, auto value_of) {
    FrameArray a = integer_array(name, true, type, n_cells);
    for (std::size_t c = 0; c < n_cells; ++c) a.integer[c] = value_of(cells[c]);
    take(a);
  };
  cell_integers("gid", FrameValue::i64, [&](LocalIndex t) { return tets.gid[t]; });
  cell_integers("piece", FrameValue::i32, [&](LocalIndex t) { return tets.piece[t]; });
  cell_integers("body", FrameValue::i32,
                [&](LocalIndex t) { return model.pieces.body_of(tets.piece[t]); });
  cell_integers("material", FrameValue::i32, [&](LocalIndex t) { return tets.material[t]; });

  if (wants("stress")) {
    FrameArray sigma = real_array("stress", true, 9, n_cells);
    FrameArray mises = real_array("von_mises", true, 1, n_cells);
    for (std::size_t c = 0; c < n_cells; ++c) {
      const Mat3 cauchy = elastic_cauchy_stress(model, cells[c]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) sigma.real[9 * c + 3 * i + j] = cauchy(i, j);
      const Mat3 dev = cauchy - cauchy.trace() / 3.0 * Mat3::Identity();
      mises.real[c] = std::sqrt(1.5 * dev.squaredNorm());
    }
    take(sigma);
    take(mises);
  }
  for (const FrameField& f : extra) {
    FrameArray a = f.per_cell ? filtered(f, static_cast<std::size_t>(tets.size()), cells)
                              : filtered(f, static_cast<std::size_t>(nodes.size()), points);
    take(a);
  }
}

std::vector<FrameArray> tet_frame_arrays(const Model& model, const std::vector<LocalIndex>& cells,
                                         const std::vector<LocalIndex>& points,
                                         const std::vector<std::string>& fields,
                                         const std::vector<FrameField>& extra) {
  std::vector<FrameArray> arrays;
  for_each_tet_frame_array(model, cells, points, fields, extra,
                           [&](FrameArray& a) { arrays.push_back(std::move(a)); });
  return arrays;
}

}  // namespace fdem
