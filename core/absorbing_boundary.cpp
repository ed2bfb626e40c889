#include "core/absorbing_boundary.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"

namespace fdem {

namespace {

using Triple = std::array<LocalIndex, 3>;

// The nodes of face k of tet t (the face opposite node k), in the tet's order, and sorted.
Triple face_nodes(const TetArrays& tets, LocalIndex t, int k) {
  Triple f{};
  int m = 0;
  for (int i = 0; i < 4; ++i)
    if (i != k) f[m++] = tets.nodes[4 * static_cast<std::size_t>(t) + i];
  return f;
}

Triple sorted(Triple f) {
  std::sort(f.begin(), f.end());
  return f;
}

bool inside(const RegionSpec& r, const Vec3& x) {
  for (int k = 0; k < 3; ++k)
    if (x[k] < r.min[k] || x[k] > r.max[k]) return false;
  return true;
}

}  // namespace

std::vector<AbsorbingFace> find_absorbing_faces(const std::vector<AbsorbingSpec>& specs,
                                                const Model& model) {
  std::vector<AbsorbingFace> out;
  if (specs.empty()) return out;
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  // Every held tet's faces by their sorted nodes: a face touching an owned node has all its tets
  // held here, so a count of 1 means a boundary face of the whole mesh.
  std::vector<Triple> all;
  all.reserve(4 * static_cast<std::size_t>(tets.size()));
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int k = 0; k < 4; ++k) all.push_back(sorted(face_nodes(tets, t, k)));
  std::sort(all.begin(), all.end());
  // Faces bonded by a cohesive joint (intact or broken: the mesh's interior at t = 0).
  std::vector<Triple> bonded;
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    for (int side = 0; side < 2; ++side) {
      const LocalIndex* n = model.joints.nodes.data() + 6 * static_cast<std::size_t>(j) + 3 * side;
      bonded.push_back(sorted({n[0], n[1], n[2]}));
    }
  std::sort(bonded.begin(), bonded.end());

  for (LocalIndex t = 0; t < tets.size(); ++t) {
    const std::int32_t body = model.pieces.body_of(tets.piece[t]);
    for (int k = 0; k < 4; ++k) {
      const Triple f = face_nodes(tets, t, k);
      if (f[0] >= nodes.n_owned && f[1] >= nodes.n_owned && f[2] >= nodes.n_owned) continue;
      const Triple key = sorted(f);
      const auto range = std::equal_range(all.begin(), all.end(), key);
      if (range.second - range.first != 1) continue;
      if (std::binary_search(bonded.begin(), bonded.end(), key)) continue;
      const Vec3 a = nodes.x0(f[0]), b = nodes.x0(f[1]), c = nodes.x0(f[2]);
      std::int32_t spec = -1;
      for (std::size_t s = 0; s < specs.size() && spec < 0; ++s) {
        const AbsorbingSpec& sp = specs[s];
        if (!sp.bodies.empty() &&
            std::find(sp.bodies.begin(), sp.bodies.end(), body) == sp.bodies.end())
          continue;
        if (inside(sp.region, a) && inside(sp.region, b) && inside(sp.region, c))
          spec = static_cast<std::int32_t>(s);
      }
      if (spec < 0) continue;
      AbsorbingFace face;
      face.tet = t;
      face.face = k;
      face.spec = spec;
      Vec3 n = (b - a).cross(c - a);
      face.area = 0.5 * n.norm();
      n /= n.norm();
      const Vec3 opposite = nodes.x0(tets.nodes[4 * static_cast<std::size_t>(t) + k]);
      if (n.dot(a - opposite) < 0.0) n = -n;  // outward: away from the tet's fourth node
      face.normal = n;
      const MaterialProperties& m = model.materials[static_cast<std::size_t>(tets.material[t])];
      face.z_p = std::sqrt(m.density * m.lame.p_wave_modulus());
      face.z_s = std::sqrt(m.density * m.lame.mu);
      out.push_back(face);
    }
  }
  return out;
}

AbsorbingBoundary::AbsorbingBoundary(std::vector<AbsorbingSpec> specs, const Model& model)
    : specs_(std::move(specs)) {
  rebind(model);
}

void AbsorbingBoundary::rebind(const Model& model) {
  faces_ = find_absorbing_faces(specs_, model);
  const NodeArrays& nodes = model.nodes;
  nodes_.clear();
  for (const AbsorbingFace& f : faces_)
    for (LocalIndex n : face_nodes(model.tets, f.tet, f.face))
      if (n < nodes.n_owned) nodes_.push_back(n);
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  slot_.assign(static_cast<std::size_t>(nodes.size()), -1);
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    slot_[static_cast<std::size_t>(nodes_[i])] = static_cast<std::int32_t>(i);
  force_.assign(3 * nodes_.size(), 0.0);
}

double AbsorbingBoundary::add_forces(double dt, Model& model) {
  NodeArrays& nodes = model.nodes;
  std::fill(force_.begin(), force_.end(), 0.0);
  double f[9];
  for (const AbsorbingFace& face : faces_) {
    const Triple n = face_nodes(model.tets, face.tet, face.face);
    const double* v[3] = {&nodes.v[3 * static_cast<std::size_t>(n[0])],
                          &nodes.v[3 * static_cast<std::size_t>(n[1])],
                          &nodes.v[3 * static_cast<std::size_t>(n[2])]};
    lk_face_forces(v, face.normal, face.area, face.z_p, face.z_s, f);
    for (int i = 0; i < 3; ++i) {
      const auto at = static_cast<std::size_t>(n[i]);
      for (int k = 0; k < 3; ++k) nodes.f[3 * at + k] += f[3 * i + k];
      if (slot_[at] >= 0)
        for (int k = 0; k < 3; ++k)
          force_[3 * static_cast<std::size_t>(slot_[at]) + k] += f[3 * i + k];
    }
  }
  return dissipation_after(dt, model);  // v still holds v_{n−½}
}

double AbsorbingBoundary::dissipation_after(double dt, const Model& model) const {
  double d = 0.0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const double* v = &model.nodes.v[3 * static_cast<std::size_t>(nodes_[i])];
    d -= force_[3 * i] * v[0] + force_[3 * i + 1] * v[1] + force_[3 * i + 2] * v[2];
  }
  return 0.5 * dt * d;
}

double AbsorbingBoundary::max_rate(const Model& model) const {
  std::vector<double> c(nodes_.size(), 0.0);
  for (const AbsorbingFace& face : faces_)
    for (LocalIndex n : face_nodes(model.tets, face.tet, face.face))
      if (n < model.nodes.n_owned)
        c[static_cast<std::size_t>(slot_[static_cast<std::size_t>(n)])] +=
            face.z_p * face.area / 3.0;
  double rate = 0.0;
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    rate = std::max(rate, c[i] / model.nodes.mass[static_cast<std::size_t>(nodes_[i])]);
  return rate;
}

std::vector<std::int64_t> AbsorbingBoundary::counted_faces(const Model& model) const {
  std::vector<std::int64_t> count(specs_.size(), 0);
  for (const AbsorbingFace& face : faces_) {
    const Triple n = face_nodes(model.tets, face.tet, face.face);
    const LocalIndex first = *std::min_element(n.begin(), n.end(), [&](LocalIndex p, LocalIndex q) {
      return model.nodes.gid[static_cast<std::size_t>(p)] <
             model.nodes.gid[static_cast<std::size_t>(q)];
    });
    if (first < model.nodes.n_owned) ++count[static_cast<std::size_t>(face.spec)];
  }
  return count;
}

std::vector<double> AbsorbingBoundary::counted_area(const Model& model) const {
  std::vector<double> area(specs_.size(), 0.0);
  for (const AbsorbingFace& face : faces_) {
    const Triple n = face_nodes(model.tets, face.tet, face.face);
    const LocalIndex first = *std::min_element(n.begin(), n.end(), [&](LocalIndex p, LocalIndex q) {
      return model.nodes.gid[static_cast<std::size_t>(p)] <
             model.nodes.gid[static_cast<std::size_t>(q)];
    });
    if (first < model.nodes.n_owned) area[static_cast<std::size_t>(face.spec)] += face.area;
  }
  return area;
}

}  // namespace fdem
