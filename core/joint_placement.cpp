#include "core/joint_placement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include "core/checked_cast.hpp"
#include "core/error.hpp"
#include "core/joint_strength.hpp"

namespace fdem {

namespace {

// Joint penalty p_n = p_t = joint_penalty_factor × Young's modulus.  A joint acts like a layer of
// modulus p and thickness h in series with the tets (Munjiza 2004, p. 79), so an intact jointed
// mesh is softer than the continuum by about E/p.  Measured (tests/verification/test_fracture.cpp,
// free–free axial bar of 20 × 1 × 1 Kuhn cells): the jointed bar's frequency is 1.9 % below the
// continuous mesh's with 50 E; 10 E loses several per cent.  The price of the stiffer penalty is
// a smaller stable step (the joint springs' ω² adds to the elastic one).
constexpr double joint_penalty_factor = 50.0;
// Laws are shared by joints whose element size h falls in the same bin of this ratio (h is
// rounded to the bin's centre, at most 1 % off), so a graded mesh needs few law objects.
constexpr double element_size_bin_ratio = 1.02;

// A triangular face of a tet in a body mesh: sorted mesh node ids, the tet, its fourth corner.
struct MeshFace {
  std::array<LocalIndex, 3> key;
  LocalIndex tet;
  std::int8_t opposite;
};

// All faces of a body mesh sorted by their node triple: interior faces appear twice in a row.
std::vector<MeshFace> sorted_faces(const BodyMesh& mesh) {
  const LocalIndex n_tets = static_cast<LocalIndex>(mesh.tets.size() / 4);
  std::vector<MeshFace> faces;
  faces.reserve(4 * static_cast<std::size_t>(n_tets));
  for (LocalIndex t = 0; t < n_tets; ++t)
    for (int skip = 0; skip < 4; ++skip) {
      MeshFace f{{0, 0, 0}, t, static_cast<std::int8_t>(skip)};
      int k = 0;
      for (int c = 0; c < 4; ++c)
        if (c != skip) f.key[k++] = mesh.tets[4 * t + c];
      std::sort(f.key.begin(), f.key.end());
      faces.push_back(f);
    }
  std::sort(faces.begin(), faces.end(), [](const MeshFace& a, const MeshFace& b) {
    return a.key != b.key ? a.key < b.key : a.tet < b.tet;
  });
  return faces;
}

// A pair of coincident boundary triangles of two pieces of one body mesh: mesh tets and mesh
// nodes, b[i] at the position of a[i].
struct TouchingFaces {
  LocalIndex tet_a, tet_b;
  LocalIndex a[3], b[3];
};

// Boundary triangles of a body mesh that coincide (node positions within tol) with a boundary
// triangle of another piece of the same mesh, each touching pair once (`joints: interfaces`).
// A boundary face of piece P is matched with each piece Q > P that has a boundary node at the
// position of its first node: its i-th node's partner is the lowest-numbered boundary node of Q
// within tol of it (in a conforming mesh the only one).
std::vector<TouchingFaces> touching_piece_faces(const BodyMesh& mesh,
                                                const std::vector<MeshFace>& faces, double tol) {
  const LocalIndex n_nodes = static_cast<LocalIndex>(mesh.coords.size() / 3);
  const auto tet_piece = connected_pieces(mesh.tets, n_nodes, nullptr);
  const auto cell_of = [&](const Vec3& x) { return tolerance_cell(x, tol); };
  std::vector<const MeshFace*> boundary;
  std::map<std::array<LocalIndex, 3>, const MeshFace*> by_key;
  std::map<std::array<std::int64_t, 3>, std::vector<LocalIndex>> grid;
  std::vector<std::int32_t> node_piece(n_nodes, -1);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const bool paired = (i + 1 < faces.size() && faces[i + 1].key == faces[i].key) ||
                        (i > 0 && faces[i - 1].key == faces[i].key);
    if (paired) continue;
    boundary.push_back(&faces[i]);
    by_key[faces[i].key] = &faces[i];
    for (LocalIndex m : faces[i].key)
      if (node_piece[m] < 0) {
        node_piece[m] = tet_piece[faces[i].tet];
        grid[cell_of(vec3_at(mesh.coords.data(), m))].push_back(m);
      }
  }
  // (piece, node) of the boundary nodes of other pieces at the position of mesh node m: for each
  // piece its lowest-numbered node there, pieces ascending.
  using Partner = std::pair<std::int32_t, LocalIndex>;
  const auto coincident = [&](LocalIndex m, std::vector<Partner>& out) {
    out.clear();
    const Vec3 x = vec3_at(mesh.coords.data(), m);
    const auto c = cell_of(x);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto g = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (g == grid.end()) continue;
          for (LocalIndex n : g->second)
            if (node_piece[n] != node_piece[m] &&
                (vec3_at(mesh.coords.data(), n) - x).norm() <= tol)
              out.emplace_back(node_piece[n], n);
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end(),
                          [](const Partner& p, const Partner& q) { return p.first == q.first; }),
              out.end());
  };
  const auto in_piece = [](const std::vector<Partner>& list, std::int32_t piece) {
    const auto it = std::lower_bound(list.begin(), list.end(), Partner{piece, 0});
    return it != list.end() && it->first == piece ? it->second : LocalIndex{-1};
  };
  std::vector<TouchingFaces> out;
  std::vector<Partner> first, second, third;
  for (const MeshFace* f : boundary) {
    const std::int32_t piece = tet_piece[f->tet];
    coincident(f->key[0], first);
    if (first.empty()) continue;
    coincident(f->key[1], second);
    coincident(f->key[2], third);
    for (const auto& [other, c0] : first) {
      if (other < piece) continue;  // the pair is found from the lower piece
      TouchingFaces t{f->tet, -1, {f->key[0], f->key[1], f->key[2]}, {c0, -1, -1}};
      t.b[1] = in_piece(second, other);
      t.b[2] = in_piece(third, other);
      if (t.b[1] < 0 || t.b[2] < 0) continue;
      std::array<LocalIndex, 3> key = {t.b[0], t.b[1], t.b[2]};
      std::sort(key.begin(), key.end());
      const auto it = by_key.find(key);
      if (it == by_key.end()) continue;  // three coincident nodes that are not one triangle
      t.tet_b = it->second->tet;
      out.push_back(t);
    }
  }
  return out;
}

// A joint before ordering: tets A, B (model indices) and the model nodes of each face, b_i
// coincident with a_i.
struct JointDraft {
  LocalIndex tet_a, tet_b;
  LocalIndex a[3], b[3];
  std::int32_t group;  // law group: material index, or n_materials + interface index
};

}  // namespace

// Places the cohesive joints of `joints: all` bodies (every interior face) and of `interfaces:`
// (boundary faces of body A coinciding with boundary faces of body B at t = 0), resolves their
// laws, and stores them in model.joints in canonical order.
void place_joints(const Scene& scene, const std::vector<BodyMesh>& meshes,
                  const std::vector<std::vector<LocalIndex>>& model_tet, const Vec3& extent,
                  Model& model) {
  const std::int32_t n_materials = static_cast<std::int32_t>(scene.materials.size());
  bool any = !scene.interfaces.empty();
  for (const BodySpec& body : scene.bodies) any = any || body.joints != JointPlacement::none;
  if (!any) return;

  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  // Model node of body b's mesh tet `local` at mesh node m.
  const auto node_at = [&](std::size_t b, LocalIndex local, LocalIndex m) {
    const LocalIndex t = model_tet[b][local];
    for (int c = 0; c < 4; ++c)
      if (meshes[b].tets[4 * local + c] == m) return tets.nodes[4 * t + c];
    FDEM_VERIFY(false, "mesh node belongs to the tet");
    return LocalIndex{-1};
  };
  std::vector<JointDraft> drafts;
  // Joint between mesh tets (ba, la) and (bb, lb) over the face with mesh nodes ma (in body ba)
  // coincident with mb (in body bb).
  const auto add = [&](std::size_t ba, LocalIndex la, const LocalIndex(&ma)[3], std::size_t bb,
                       LocalIndex lb, const LocalIndex(&mb)[3], std::int32_t group) {
    JointDraft d;
    d.tet_a = model_tet[ba][la];
    d.tet_b = model_tet[bb][lb];
    d.group = group;
    for (int i = 0; i < 3; ++i) {
      d.a[i] = node_at(ba, la, ma[i]);
      d.b[i] = node_at(bb, lb, mb[i]);
    }
    if (tets.gid[d.tet_a] > tets.gid[d.tet_b]) {  // canonical: A has the smaller gid
      std::swap(d.tet_a, d.tet_b);
      for (int i = 0; i < 3; ++i) std::swap(d.a[i], d.b[i]);
    }
    LocalIndex opposite = -1;
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * d.tet_a + c];
      if (n != d.a[0] && n != d.a[1] && n != d.a[2]) opposite = n;
    }
    if (joint_face_turned(nodes.x0(d.a[0]), nodes.x0(d.a[1]), nodes.x0(d.a[2]),
                          nodes.x0(opposite))) {
      std::swap(d.a[1], d.a[2]);
      std::swap(d.b[1], d.b[2]);
    }
    drafts.push_back(d);
  };

  const double tol = matching_tolerance(extent);
  std::vector<std::vector<MeshFace>> faces(meshes.size());
  for (std::size_t b = 0; b < meshes.size(); ++b) {
    const bool jointed = scene.bodies[b].joints == JointPlacement::all;
    bool in_interface = false;
    for (const InterfaceSpec& i : scene.interfaces)
      in_interface =
          in_interface || i.body_a == static_cast<int>(b) || i.body_b == static_cast<int>(b);
    const bool bonded_pieces = scene.bodies[b].joints == JointPlacement::interfaces;
    if (!jointed && !in_interface && !bonded_pieces) continue;
    faces[b] = sorted_faces(meshes[b]);
    const auto& f = faces[b];
    for (std::size_t i = 0; i + 2 < f.size(); ++i)
      if (f[i].key == f[i + 2].key)
        throw InputError(non_manifold_message(scene.bodies[b].name, meshes[b].source,
                                              {f[i].key[0], f[i].key[1], f[i].key[2]}));
    if (bonded_pieces) {  // mortar: joints where the body's pieces touch at t = 0
      const std::size_t before = drafts.size();
      for (const TouchingFaces& t : touching_piece_faces(meshes[b], f, tol))
        add(b, t.tet_a, t.a, b, t.tet_b, t.b, scene.bodies[b].material);
      if (drafts.size() == before)
        throw InputError(no_touching_pieces_message(scene, b, meshes[b].source));
    }
    if (!jointed) continue;
    std::size_t interior = 0;  // faces shared by two tets: one joint each (reserved: no slack)
    for (std::size_t i = 0; i + 1 < f.size(); ++i)
      if (f[i].key == f[i + 1].key) ++interior, ++i;
    drafts.reserve(drafts.size() + interior);
    std::vector<std::uint8_t> on_boundary(meshes[b].coords.size() / 3, 0);  // per mesh node
    for (std::size_t i = 0; i < f.size(); ++i)
      if (i + 1 < f.size() && f[i].key == f[i + 1].key) {
        const LocalIndex m[3] = {f[i].key[0], f[i].key[1], f[i].key[2]};
        add(b, f[i].tet, m, b, f[i + 1].tet, m, scene.bodies[b].material);
        ++i;
      } else {  // a face of one tet: the mesh boundary
        for (LocalIndex n : f[i].key) on_boundary[static_cast<std::size_t>(n)] = 1;
      }
    // Enclosed tets: no corner on the boundary (parallel/enclosed_tets finds the same without
    // a whole mesh).
    model.tets.enclosed.resize(static_cast<std::size_t>(tets.size()), 0);
    for (std::size_t t = 0; t < model_tet[b].size(); ++t) {
      bool enclosed = true;
      for (int c = 0; c < 4; ++c)
        enclosed = enclosed && !on_boundary[static_cast<std::size_t>(meshes[b].tets[4 * t + c])];
      model.tets.enclosed[static_cast<std::size_t>(model_tet[b][t])] = enclosed ? 1 : 0;
    }
  }

  // Interfaces: match boundary nodes by position (within tol), then faces.
  for (std::size_t k = 0; k < scene.interfaces.size(); ++k) {
    const InterfaceSpec& spec = scene.interfaces[k];
    const std::size_t ba = spec.body_a, bb = spec.body_b;
    const auto boundary = [&](std::size_t b) {
      std::vector<MeshFace> out;
      const auto& f = faces[b];
      for (std::size_t i = 0; i < f.size(); ++i) {
        const bool paired =
            (i + 1 < f.size() && f[i + 1].key == f[i].key) || (i > 0 && f[i - 1].key == f[i].key);
        if (!paired) out.push_back(f[i]);
      }
      return out;
    };
    const std::vector<MeshFace> faces_a = boundary(ba), faces_b = boundary(bb);
    // Hash grid of B's boundary nodes with cells of size tol: a match lies in a neighbour cell.
    const auto cell_of = [&](const Vec3& x) { return tolerance_cell(x, tol); };
    const double* xb = meshes[bb].coords.data();
    const double* xa = meshes[ba].coords.data();
    std::map<std::array<std::int64_t, 3>, std::vector<LocalIndex>> grid;
    for (const MeshFace& f : faces_b)
      for (LocalIndex m : f.key) {
        auto& cell = grid[cell_of(vec3_at(xb, m))];
        if (std::find(cell.begin(), cell.end(), m) == cell.end()) cell.push_back(m);
      }
    // A's mesh node → the lowest-numbered boundary node of B within tol of it (or −1).
    std::map<LocalIndex, LocalIndex> match;
    const auto partner = [&](LocalIndex m) {
      const auto it = match.find(m);
      if (it != match.end()) return it->second;
      const Vec3 x = vec3_at(xa, m);
      const auto c = cell_of(x);
      LocalIndex found = -1;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto g = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (g == grid.end()) continue;
            for (LocalIndex n : g->second)
              if ((vec3_at(xb, n) - x).norm() <= tol && (found < 0 || n < found)) found = n;
          }
      return match[m] = found;
    };
    std::map<std::array<LocalIndex, 3>, const MeshFace*> by_key;
    for (const MeshFace& f : faces_b) by_key[f.key] = &f;
    const std::size_t before = drafts.size();
    for (const MeshFace& fa : faces_a) {
      LocalIndex mb[3];
      bool all = true;
      for (int i = 0; i < 3; ++i) all = all && (mb[i] = partner(fa.key[i])) >= 0;
      if (!all) continue;
      std::array<LocalIndex, 3> key = {mb[0], mb[1], mb[2]};
      std::sort(key.begin(), key.end());
      const auto it = by_key.find(key);
      if (it == by_key.end()) continue;  // three coincident nodes that are not one face of B
      const LocalIndex ma[3] = {fa.key[0], fa.key[1], fa.key[2]};
      add(ba, fa.tet, ma, bb, it->second->tet, mb, n_materials + static_cast<std::int32_t>(k));
    }
    if (drafts.size() == before) throw InputError(no_interface_match_message(scene, k, tol));
  }

  release(faces);  // the joints are drafted: the face lists go before the joint arrays come

  // Canonical order: ascending (gid A, gid B); a joint's gid is its rank in it.
  std::vector<std::size_t> order(drafts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) {
    const GlobalId pa = tets.gid[drafts[p].tet_a], qa = tets.gid[drafts[q].tet_a];
    return pa != qa ? pa < qa : tets.gid[drafts[p].tet_b] < tets.gid[drafts[q].tet_b];
  });
  // Laws: one per (group, element-size bin, strength bin) in use, numbered in ascending key.
  JointArrays& joints = model.joints;
  joints.resize(local_count(drafts.size(), "joints"));
  // A joint's law key, from its tets and area (computed twice rather than stored per joint).
  const auto law_key = [&](std::size_t j) {
    return JointLawKey{
        drafts[order[j]].group,
        joint_size_bin(tets.volume0[joints.tets[2 * j]], tets.volume0[joints.tets[2 * j + 1]],
                       joints.area0[j]),
        joint_strength_bin(scene, drafts[order[j]].group, joints.gid[j], model.gid_offset)};
  };
  std::set<JointLawKey> used;
  for (std::size_t j = 0; j < order.size(); ++j) {
    const JointDraft& d = drafts[order[j]];
    joints.gid[j] = model.gid_offset + static_cast<GlobalId>(j);
    for (int i = 0; i < 3; ++i) {
      joints.nodes[6 * j + i] = d.a[i];
      joints.nodes[6 * j + 3 + i] = d.b[i];
    }
    joints.tets[2 * j] = d.tet_a;
    joints.tets[2 * j + 1] = d.tet_b;
    joints.area0[j] = joint_face_area(nodes.x0(d.a[0]), nodes.x0(d.a[1]), nodes.x0(d.a[2]));
    used.insert(law_key(j));
  }
  const std::vector<JointLawKey> keys(used.begin(), used.end());  // ascending
  for (const JointLawKey& key : keys) model.joint_laws.push_back(joint_law(scene, key));
  for (std::size_t j = 0; j < order.size(); ++j)
    joints.law[j] = static_cast<std::int32_t>(
        std::lower_bound(keys.begin(), keys.end(), law_key(j)) - keys.begin());
}

double matching_tolerance(const Vec3& extent) {
  return 1e-9 * std::max(extent.norm(), 1e-300);
}

std::array<std::int64_t, 3> tolerance_cell(const Vec3& x, double tol) {
  std::array<std::int64_t, 3> cell{};
  for (int k = 0; k < 3; ++k) {
    const auto c = floor_to_integer<std::int64_t>(x[k] / tol);
    if (!c)
      throw InputError("a mesh node at (" + std::to_string(x[0]) + ", " + std::to_string(x[1]) +
                       ", " + std::to_string(x[2]) + ") m is too far from the origin to match " +
                       "touching faces within " + std::to_string(tol) + " m");
    cell[k] = *c;
  }
  return cell;
}

bool joint_face_turned(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& opposite) {
  const Vec3 normal = (a1 - a0).cross(a2 - a0);
  return normal.dot(opposite - a0) > 0.0;
}

double joint_face_area(const Vec3& a0, const Vec3& a1, const Vec3& a2) {
  return 0.5 * (a1 - a0).cross(a2 - a0).norm();
}

long joint_size_bin(double volume_a, double volume_b, double area) {
  const double h = 0.5 * (3.0 * volume_a / area + 3.0 * volume_b / area);
  return std::lround(std::log(h) / std::log(element_size_bin_ratio));
}

const FractureSpec& group_fracture(const Scene& scene, std::int64_t group) {
  const auto n_materials = static_cast<std::int64_t>(scene.materials.size());
  if (group < n_materials) {
    const MaterialSpec& m = scene.materials[static_cast<std::size_t>(group)];
    FDEM_VERIFY(m.fracture.has_value(), "joints: all needs a fracture block (reader checks)");
    return *m.fracture;
  }
  return scene.interfaces[static_cast<std::size_t>(group - n_materials)].fracture;
}

long joint_strength_bin(const Scene& scene, std::int64_t group, GlobalId gid, GlobalId gid_offset) {
  return strength_bin(group_fracture(scene, group).strength_distribution,
                      static_cast<std::uint64_t>(gid - gid_offset));
}

JointLawSpec joint_law(const Scene& scene, const JointLawKey& key) {
  const auto n_materials = static_cast<std::int64_t>(scene.materials.size());
  JointLawSpec law;
  law.fracture = group_fracture(scene, key.group);
  double young;
  if (key.group < n_materials) {
    const MaterialSpec& m = scene.materials[static_cast<std::size_t>(key.group)];
    law.origin = "material '" + m.name + "'";
    young = m.elastic.young;
  } else {
    const InterfaceSpec& spec = scene.interfaces[static_cast<std::size_t>(key.group - n_materials)];
    law.origin = "interface '" + scene.bodies[spec.body_a].name + "'-'" +
                 scene.bodies[spec.body_b].name + "'";
    young = std::min(scene.materials[scene.bodies[spec.body_a].material].elastic.young,
                     scene.materials[scene.bodies[spec.body_b].material].elastic.young);
  }
  law.auto_penalty = joint_penalty_factor * young;
  const FractureSpec& f = law.fracture;
  law.normal_penalty = f.normal_penalty > 0.0 ? f.normal_penalty : law.auto_penalty;
  law.tangential_penalty = f.tangential_penalty > 0.0 ? f.tangential_penalty : law.auto_penalty;
  law.element_size = std::pow(element_size_bin_ratio, static_cast<double>(key.size_bin));
  if (key.strength_bin != 0) {  // bin 0 keeps the block's values bit for bit
    law.strength_scale = strength_bin_factor(static_cast<long>(key.strength_bin));
    law.fracture.tensile_strength *= law.strength_scale;
    law.fracture.cohesion *= law.strength_scale;
  }
  return law;
}

std::string non_manifold_message(const std::string& body, const std::string& source,
                                 const std::array<std::int64_t, 3>& mesh_nodes) {
  std::ostringstream msg;
  msg << "body '" << body << "' (" << source
      << "): a triangle is shared by more than two tetrahedra (mesh nodes " << mesh_nodes[0] + 1
      << ", " << mesh_nodes[1] + 1 << ", " << mesh_nodes[2] + 1
      << "); joints need a conforming, manifold tetrahedral mesh";
  return msg.str();
}

std::string no_touching_pieces_message(const Scene& scene, std::size_t body,
                                       const std::string& source) {
  return scene.source_path + ": body '" + scene.bodies[body].name + "' (" + source +
         ") has joints: interfaces, but no two of its pieces share a triangle at t = 0. Touching "
         "pieces need identical triangles (a generated wall with mortar_gap 0, conforming cells) "
         "to be bonded.";
}

std::string no_interface_match_message(const Scene& scene, std::size_t k, double tol) {
  const InterfaceSpec& spec = scene.interfaces[k];
  std::ostringstream msg;
  msg << scene.source_path << ": interfaces[" << k << "] between '"
      << scene.bodies[spec.body_a].name << "' and '" << scene.bodies[spec.body_b].name
      << "': no boundary triangle of one body coincides with a boundary triangle of the other "
         "at t = 0 (node tolerance "
      << tol
      << " m). Interface joints need conforming meshes: the two bodies must touch with "
         "identical triangles (same three node positions), as box meshes sharing a face or "
         "a Gmsh mesh with shared surfaces give.";
  return msg.str();
}

}  // namespace fdem
