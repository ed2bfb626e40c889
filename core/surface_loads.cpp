#include "core/surface_loads.hpp"

#include <algorithm>
#include <array>

namespace fdem {

namespace {

using FaceKey = std::array<LocalIndex, 3>;  // node indices, ascending

FaceKey key_of(LocalIndex a, LocalIndex b, LocalIndex c) {
  FaceKey k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace

SurfaceFaces select_surface_faces(const Model& model, const LoadSpec& load) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  // Every face of the local tets, with the faces of joints, sorted by key: a key met once that is
  // no joint's face is a boundary face.
  struct Entry {
    FaceKey key;
    LocalIndex tet;  // −1: a joint's face
    int corner;
  };
  std::vector<Entry> entries;
  entries.reserve(4 * static_cast<std::size_t>(tets.size()) + 2 * model.joints.size());
  for (LocalIndex t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c) {
      const LocalIndex* n = tets.nodes.data() + 4 * static_cast<std::size_t>(t);
      const int* f = tet_face_corners[c];
      entries.push_back({key_of(n[f[0]], n[f[1]], n[f[2]]), t, c});
    }
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    for (int side = 0; side < 2; ++side) {
      const LocalIndex* n = model.joints.nodes.data() + 6 * static_cast<std::size_t>(j) + 3 * side;
      entries.push_back({key_of(n[0], n[1], n[2]), -1, 0});
    }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.key != b.key ? a.key < b.key : a.tet < b.tet;
  });
  // A physical surface: its triangles by their sorted corners (the file's coordinates, which the
  // model's reference positions are, bit for bit).
  using Corner = std::array<double, 3>;
  using Triangle = std::array<Corner, 3>;
  const auto triangle_of = [](Corner a, Corner b, Corner c) {
    Triangle t{a, b, c};
    std::sort(t.begin(), t.end());
    return t;
  };
  std::vector<Triangle> wanted;
  const std::vector<double>& tri = load.surface.triangles;
  for (std::size_t i = 0; i + 9 <= tri.size(); i += 9)
    wanted.push_back(triangle_of({tri[i], tri[i + 1], tri[i + 2]},
                                 {tri[i + 3], tri[i + 4], tri[i + 5]},
                                 {tri[i + 6], tri[i + 7], tri[i + 8]}));
  std::sort(wanted.begin(), wanted.end());
  const auto corner = [&](LocalIndex n) {
    const Vec3 X = nodes.x0(n);
    return Corner{X[0], X[1], X[2]};
  };
  std::vector<std::pair<LocalIndex, int>> chosen;  // (tet, corner)
  const auto inside = [&](LocalIndex n) {
    const Vec3 X = nodes.x0(n);
    return (X.array() >= load.region->min.array()).all() &&
           (X.array() <= load.region->max.array()).all();
  };
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i + 1;
    while (j < entries.size() && entries[j].key == entries[i].key) ++j;
    const Entry& e = entries[i];
    const FaceKey& k = e.key;
    const bool has_owned = k[0] < nodes.n_owned || k[1] < nodes.n_owned || k[2] < nodes.n_owned;
    if (j == i + 1 && e.tet >= 0 && has_owned) {
      bool selected = false;
      if (load.region) {
        selected = inside(k[0]) && inside(k[1]) && inside(k[2]);
      } else {
        const std::int32_t body = model.pieces.body_of(tets.piece[e.tet]);
        selected = std::find(load.bodies.begin(), load.bodies.end(), body) != load.bodies.end();
        if (selected && !tri.empty())
          selected = std::binary_search(wanted.begin(), wanted.end(),
                                        triangle_of(corner(k[0]), corner(k[1]), corner(k[2])));
      }
      if (selected) chosen.emplace_back(e.tet, e.corner);
    }
    i = j;
  }
  std::sort(chosen.begin(), chosen.end(), [&](const auto& a, const auto& b) {
    return tets.gid[a.first] != tets.gid[b.first] ? tets.gid[a.first] < tets.gid[b.first]
                                                  : a.second < b.second;
  });
  SurfaceFaces faces;
  for (const auto& [t, c] : chosen) {
    const LocalIndex* n = tets.nodes.data() + 4 * static_cast<std::size_t>(t);
    std::array<LocalIndex, 3> f = {n[tet_face_corners[c][0]], n[tet_face_corners[c][1]],
                                   n[tet_face_corners[c][2]]};
    // Outward whatever the tet's corner order: away from the opposite corner at t = 0.
    const Vec3 X0 = nodes.x0(f[0]);
    const Vec3 normal = (nodes.x0(f[1]) - X0).cross(nodes.x0(f[2]) - X0);
    if (normal.dot(X0 - nodes.x0(n[c])) < 0.0) std::swap(f[1], f[2]);
    faces.nodes.insert(faces.nodes.end(), f.begin(), f.end());
    faces.tet.push_back(tets.gid[t]);
    faces.owned.push_back(tets.is_owned(t) ? 1 : 0);
  }
  faces.corner_force.assign(3 * faces.tet.size(), 0.0);
  return faces;
}

void add_surface_forces(const SurfaceLoadSpec& spec, double factor, SurfaceFaces& faces,
                        NodeArrays& nodes) {
  const bool current = spec.kind == SurfaceLoadSpec::Kind::pressure && spec.follower;
  const auto position = [&](LocalIndex n) -> Vec3 {
    return current ? Vec3(vec3_at(nodes.x.data(), n)) : Vec3(nodes.x0(n));
  };
  const double p = factor * spec.pressure;       // Pa
  const Vec3 traction = factor * spec.traction;  // Pa
  for (LocalIndex i = 0; i < faces.size(); ++i) {
    const LocalIndex* n = faces.nodes.data() + 3 * static_cast<std::size_t>(i);
    const Vec3 a = position(n[0]), b = position(n[1]), c = position(n[2]);
    const Vec3 force = spec.kind == SurfaceLoadSpec::Kind::pressure
                           ? pressure_corner_force(a, b, c, p)
                           : traction_corner_force(a, b, c, traction);
    vec3_at(faces.corner_force.data(), i) = force;
    for (int k = 0; k < 3; ++k) vec3_at(nodes.f.data(), n[k]) += force;
  }
}

double surface_force_magnitude(const SurfaceFaces& faces) {
  double sum = 0.0;
  for (LocalIndex i = 0; i < faces.size(); ++i)
    if (faces.owned[i]) sum += 3.0 * vec3_at(faces.corner_force.data(), i).norm();
  return sum;
}

double surface_power(const SurfaceFaces& faces, const NodeArrays& nodes) {
  double power = 0.0;
  for (LocalIndex i = 0; i < faces.size(); ++i) {
    const Vec3 force = vec3_at(faces.corner_force.data(), i);
    for (int k = 0; k < 3; ++k) {
      const LocalIndex n = faces.nodes[3 * static_cast<std::size_t>(i) + k];
      if (n < nodes.n_owned) power += force.dot(vec3_at(nodes.v.data(), n));
    }
  }
  return power;
}

Vec3 surface_resultant(const SurfaceFaces& faces) {
  Vec3 sum = Vec3::Zero();
  for (LocalIndex i = 0; i < faces.size(); ++i)
    if (faces.owned[i]) sum += 3.0 * vec3_at(faces.corner_force.data(), i);
  return sum;
}

}  // namespace fdem
