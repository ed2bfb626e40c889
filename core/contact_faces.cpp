#include "core/contact_faces.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/error.hpp"

namespace fdem {
namespace {

auto face_key(const FaceRecord& r) {
  return std::tie(r.group, r.node[0], r.node[1], r.node[2]);
}
auto edge_key(const EdgeRecord& r) {
  return std::tie(r.group, r.node[0], r.node[1]);
}

// Sorts by key, then by tet gid and position, so that the result is the same whatever order the
// records arrived in.
void sort_faces(std::vector<FaceRecord>& records) {
  std::sort(records.begin(), records.end(), [](const FaceRecord& a, const FaceRecord& b) {
    return std::tie(a.group, a.node[0], a.node[1], a.node[2], a.tet, a.face) <
           std::tie(b.group, b.node[0], b.node[1], b.node[2], b.tet, b.face);
  });
}

// The local tet of a surface face's record (held where the record came from).
LocalIndex surface_tet(const Model& model, const FaceRecord& s) {
  const LocalIndex t = model.tets.find(s.tet);
  FDEM_VERIFY(t >= 0, "a surface face's tet is held where its record came from");
  return t;
}

// Face f's unit normal in the reference mesh, pointing away from the opposite corner f.
Vec3 reference_outward_normal(const Model& model, LocalIndex t, int f) {
  Vec3 x[4];
  for (int c = 0; c < 4; ++c) x[c] = model.nodes.x0(model.tets.nodes[4 * t + c]);
  int w[3];
  face_corners(f, w);
  const Vec3 normal = (x[w[1]] - x[w[0]]).cross(x[w[2]] - x[w[0]]).normalized();
  return normal.dot(x[f] - x[w[0]]) > 0.0 ? Vec3(-normal) : normal;
}

}  // namespace

std::vector<FaceRecord> face_records(const Model& model, int source) {
  const TetArrays& tets = model.tets;
  std::vector<FaceRecord> records;
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;
    for (int f = 0; f < 4; ++f) {
      int w[3];
      face_corners(f, w);
      FaceRecord r{};
      r.group = tets.group_of(t);
      for (int j = 0; j < 3; ++j) r.node[j] = model.nodes.gid[tets.nodes[4 * t + w[j]]];
      std::sort(r.node, r.node + 3);
      r.tet = tets.gid[t];
      r.source = source;
      r.face = f;
      records.push_back(r);
    }
  }
  return records;
}

void keep_surface_faces(std::vector<FaceRecord>& records) {
  sort_faces(records);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i + 1;
    while (j < records.size() && face_key(records[j]) == face_key(records[i])) ++j;
    if (j == i + 1) records[kept++] = records[i];
    i = j;
  }
  records.resize(kept);
}

std::vector<EdgeRecord> edge_records(const Model& model, const std::vector<FaceRecord>& surface) {
  const TetArrays& tets = model.tets;
  std::vector<EdgeRecord> records;
  records.reserve(3 * surface.size());
  for (const FaceRecord& s : surface) {
    const LocalIndex t = surface_tet(model, s);
    const int f = static_cast<int>(s.face);
    int w[3];
    face_corners(f, w);
    const Vec3 normal = reference_outward_normal(model, t, f);
    for (int e = 0; e < 3; ++e) {
      EdgeRecord r{};
      r.group = s.group;
      r.node[0] = model.nodes.gid[tets.nodes[4 * t + w[(e + 1) % 3]]];
      r.node[1] = model.nodes.gid[tets.nodes[4 * t + w[(e + 2) % 3]]];
      if (r.node[1] < r.node[0]) std::swap(r.node[0], r.node[1]);
      r.tet = s.tet;
      r.source = s.source;
      r.face_edge = 3 * f + e;
      for (int k = 0; k < 3; ++k) r.normal[k] = normal[k];
      records.push_back(r);
    }
  }
  return records;
}

void keep_fold_edges(std::vector<EdgeRecord>& records) {
  std::sort(records.begin(), records.end(), [](const EdgeRecord& a, const EdgeRecord& b) {
    return std::tie(a.group, a.node[0], a.node[1], a.tet, a.face_edge) <
           std::tie(b.group, b.node[0], b.node[1], b.tet, b.face_edge);
  });
  const double flat = std::cos(kFoldAngleDegrees * 3.14159265358979323846 / 180.0);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i + 1;
    while (j < records.size() && edge_key(records[j]) == edge_key(records[i])) ++j;
    bool fold = j != i + 2;  // an edge of one surface face, or of three or more
    if (!fold) {
      const double* n0 = records[i].normal;
      const double* n1 = records[i + 1].normal;
      fold = !(n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] >= flat);
    }
    if (fold)
      for (std::size_t k = i; k < j; ++k) records[kept++] = records[k];
    i = j;
  }
  records.resize(kept);
}

std::vector<VertexRecord> vertex_records(const Model& model, const std::vector<FaceRecord>& surface,
                                         const std::vector<EdgeRecord>& folds) {
  const TetArrays& tets = model.tets;
  std::vector<std::pair<std::int64_t, std::int64_t>> fold_of;  // (tet, face_edge), sorted
  for (const EdgeRecord& e : folds) fold_of.emplace_back(e.tet, e.face_edge);
  std::sort(fold_of.begin(), fold_of.end());
  std::vector<VertexRecord> records;
  records.reserve(3 * surface.size());
  for (const FaceRecord& s : surface) {
    const LocalIndex t = surface_tet(model, s);
    const int f = static_cast<int>(s.face);
    int w[3];
    face_corners(f, w);
    const Vec3 normal = reference_outward_normal(model, t, f);
    bool fold[3];
    for (int e = 0; e < 3; ++e)
      fold[e] = std::binary_search(fold_of.begin(), fold_of.end(),
                                   std::make_pair(s.tet, std::int64_t{3 * f + e}));
    for (int c = 0; c < 3; ++c) {
      // Corner c ends the edges other than edge c (the one opposite it).
      const bool has_fold = fold[(c + 1) % 3] || fold[(c + 2) % 3];
      records.push_back({s.group,
                         model.nodes.gid[tets.nodes[4 * t + w[c]]],
                         s.tet,
                         s.source,
                         3 * f + c,
                         has_fold ? VertexRecord::kHasFold : 0,
                         {normal.x(), normal.y(), normal.z()}});
    }
  }
  return records;
}

void keep_fold_vertices(std::vector<VertexRecord>& records) {
  std::sort(records.begin(), records.end(), [](const VertexRecord& a, const VertexRecord& b) {
    return std::tie(a.group, a.node, a.tet, a.face_corner) <
           std::tie(b.group, b.node, b.tet, b.face_corner);
  });
  const double flat = std::cos(kFoldAngleDegrees * 3.14159265358979323846 / 180.0);
  const auto same_side = [&](const VertexRecord& a, const VertexRecord& b) {
    return a.normal[0] * b.normal[0] + a.normal[1] * b.normal[1] + a.normal[2] * b.normal[2] >=
           flat;
  };
  std::vector<VertexRecord> kept;
  std::vector<std::size_t> side_of, sides;  // per record of the vertex its side; each side's first
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i + 1;
    while (j < records.size() && records[j].group == records[i].group &&
           records[j].node == records[i].node)
      ++j;
    side_of.assign(j - i, 0);
    sides.clear();
    for (std::size_t k = i; k < j; ++k) {
      std::size_t side = 0;
      while (side < sides.size() && !same_side(records[sides[side]], records[k])) ++side;
      if (side == sides.size()) {
        sides.push_back(k);
        records[k].flags |= VertexRecord::kZoneOwner;
      }
      side_of[k - i] = side;
    }
    for (std::size_t side = 0; side < sides.size(); ++side) {
      bool folded = false;
      for (std::size_t k = i; k < j; ++k)
        folded |= side_of[k - i] == side && (records[k].flags & VertexRecord::kHasFold);
      if (!folded) continue;
      for (std::size_t k = i; k < j; ++k)
        if (side_of[k - i] == side) {
          kept.push_back(records[k]);
          kept.back().flags |= VertexRecord::kFoldVertex;
        }
    }
    i = j;
  }
  records = std::move(kept);
}

void set_contact_faces(Model& model, const std::vector<FaceRecord>& surface,
                       const std::vector<EdgeRecord>& folds,
                       const std::vector<VertexRecord>& vertices) {
  TetArrays& tets = model.tets;
  std::vector<std::uint64_t> bits(static_cast<std::size_t>(tets.size()), 0);
  const auto bits_of = [&](std::int64_t gid) -> std::uint64_t& {
    const LocalIndex t = tets.find(gid);
    FDEM_VERIFY(t >= 0, "a contact face record's tet is held here");
    return bits[static_cast<std::size_t>(t)];
  };
  for (const FaceRecord& s : surface)
    bits_of(s.tet) |= contact_face_bits::surface(static_cast<int>(s.face));
  for (const EdgeRecord& e : folds)
    bits_of(e.tet) |= contact_face_bits::fold(static_cast<int>(e.face_edge / 3),
                                              static_cast<int>(e.face_edge % 3));
  for (const VertexRecord& v : vertices) {
    const int f = static_cast<int>(v.face_corner / 3), c = static_cast<int>(v.face_corner % 3);
    if (v.flags & VertexRecord::kFoldVertex) bits_of(v.tet) |= contact_face_bits::fold_vertex(f, c);
    if ((v.flags & VertexRecord::kFoldVertex) && (v.flags & VertexRecord::kZoneOwner))
      bits_of(v.tet) |= contact_face_bits::zone_owner(f, c);
  }
  tets.contact_faces.resize(2 * bits.size());
  for (std::size_t t = 0; t < bits.size(); ++t) {
    tets.contact_faces[2 * t] = static_cast<std::int32_t>(bits[t] & 0xFFFFFFFFu);
    tets.contact_faces[2 * t + 1] = static_cast<std::int32_t>(bits[t] >> 32);
  }
}

void compute_contact_faces(Model& model) {
  std::vector<FaceRecord> faces = face_records(model, 0);
  keep_surface_faces(faces);
  std::vector<EdgeRecord> edges = edge_records(model, faces);
  keep_fold_edges(edges);
  std::vector<VertexRecord> vertices = vertex_records(model, faces, edges);
  keep_fold_vertices(vertices);
  set_contact_faces(model, faces, edges, vertices);
}

}  // namespace fdem
