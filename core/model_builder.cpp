#include "core/model_builder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include "core/checked_cast.hpp"
#include "core/contact_faces.hpp"
#include "core/error.hpp"
#include "core/joint_placement.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

struct UnionFind {
  std::vector<LocalIndex> parent;
  explicit UnionFind(LocalIndex n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  LocalIndex find(LocalIndex i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(LocalIndex a, LocalIndex b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

std::uint64_t spread_bits(std::uint64_t v) {  // 21 bits -> every third bit
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

MaterialProperties resolve_material(const MaterialSpec& spec) {
  MaterialProperties m;
  m.name = spec.name;
  m.density = spec.density;
  m.model = spec.elastic.model;
  m.young = spec.elastic.young;
  m.poisson = spec.elastic.poisson;
  m.lame = LameParameters::from_young_poisson(spec.elastic.young, spec.elastic.poisson);
  m.damping_ratio = spec.damping;
  m.contact = spec.contact;
  return m;
}

}  // namespace

std::vector<std::int32_t> connected_pieces(const std::vector<LocalIndex>& tets, LocalIndex n_nodes,
                                           std::int32_t* n_pieces) {
  UnionFind uf(n_nodes);
  const LocalIndex n_tets = static_cast<LocalIndex>(tets.size() / 4);
  for (LocalIndex t = 0; t < n_tets; ++t)
    for (int c = 1; c < 4; ++c) uf.unite(tets[4 * t], tets[4 * t + c]);
  std::vector<std::int32_t> root_piece(n_nodes, -1), piece(n_tets);
  std::int32_t count = 0;
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const LocalIndex root = uf.find(tets[4 * t]);
    if (root_piece[root] < 0) root_piece[root] = count++;
    piece[t] = root_piece[root];
  }
  if (n_pieces) *n_pieces = count;
  return piece;
}

std::uint64_t morton_key(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  // Each axis spans its own extent, but an axis m times (rounded in log2) shorter than the
  // longest gets m bits fewer, so the curve first cuts the longest axis alone until the cells
  // are about cubes. Equal stretches of the curve (the ranks' blocks at start-up) are then
  // compact: a 0.4 m thick wall is cut across its length, not through its thickness, where every
  // block would border the next over the whole wall.
  const Vec3 extent = hi - lo;
  const double longest = extent.maxCoeff();
  std::uint64_t key = 0;
  for (int k = 0; k < 3; ++k) {
    int fewer_bits = 0;
    if (extent[k] > 0.0)
      fewer_bits = std::clamp(static_cast<int>(std::lround(std::log2(longest / extent[k]))), 0, 20);
    const double cells = static_cast<double>((std::uint64_t{1} << (21 - fewer_bits)) - 1);
    double s = extent[k] > 0.0 ? (p[k] - lo[k]) / extent[k] : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    key |= spread_bits(static_cast<std::uint64_t>(s * cells)) << k;
  }
  return key;
}

void check_tet_shape(const Vec3 (&X)[4], const std::string& body, const std::string& source,
                     std::int64_t tag) {
  const double volume = tet_reference(X).volume;
  const double scale = std::pow(std::max(smallest_altitude(X), 1e-300), 3.0);
  if (!(volume > 1e-12 * scale) || !std::isfinite(volume)) {
    std::ostringstream msg;
    msg << "body '" << body << "' (" << source << "): tetrahedron " << tag
        << (volume < 0 ? " is inverted (negative volume " : " is degenerate (volume ") << volume
        << " m^3). Fix the mesh: nodes of a 4-node tetrahedron must be ordered so that "
           "(x1-x0)x(x2-x0).(x3-x0) > 0, as Gmsh writes them.";
    throw InputError(msg.str());
  }
}

TetSetup setup_tet(const Vec3 (&X)[4], const MaterialProperties& mat) {
  const TetReference ref = tet_reference(X);
  TetSetup out;
  out.dm_inv = ref.dm_inv;
  out.volume = ref.volume;
  out.mass = mat.density * ref.volume;
  // Viscosity that gives damping ratio ξ in the element's highest mode: η = 2ξμ/ω_max.
  if (mat.damping_ratio > 0.0) {
    const double k_max = tet_max_stiffness_eigenvalue(ref.dm_inv, ref.volume, mat.lame);
    const double omega = std::sqrt(k_max / (0.25 * out.mass));
    out.viscosity = 2.0 * mat.damping_ratio * mat.lame.mu / omega;
  }
  return out;
}

void add_to_piece(PieceInfo& piece, double element_mass, const Vec3 (&X)[4]) {
  piece.mass += element_mass;
  piece.centroid0 += element_mass * 0.25 * (X[0] + X[1] + X[2] + X[3]);
}

void finish_piece(PieceInfo& piece) {
  if (piece.mass > 0.0) piece.centroid0 /= piece.mass;
}

void set_dashpot_masses(Model& model) {
  TetArrays& tets = model.tets;
  for (LocalIndex t = 0; t < tets.size(); ++t)
    tets.dashpot_mass[t] =
        tets.group_of(t) == tets.piece[t] ? model.pieces[tets.piece[t]].mass : 0.0;
}

void set_initial_velocities(const Scene& scene, Model& model) {
  NodeArrays& nodes = model.nodes;
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    const PieceInfo& piece = model.pieces[nodes.piece[n]];
    const BodySpec& body = scene.bodies[piece.body];
    const Vec3 r = nodes.x0(n) - piece.centroid0;
    vec3_at(nodes.v.data(), n) = body.velocity + body.angular_velocity.cross(r);
  }
}

Model model_frame(const Scene& scene) {
  Model model;
  model.gravity = scene.gravity;
  model.gid_offset = scene.parallel.gid_offset;
  for (const auto& spec : scene.materials) model.materials.push_back(resolve_material(spec));
  for (const auto& body : scene.bodies) {
    // The reader names materials; a scene made in code gives indices (BodySpec's default, −1,
    // is none).
    if (body.material < 0 || body.material >= static_cast<int>(scene.materials.size()))
      throw InputError(scene.source_path + ": body '" + body.name + "' has material index " +
                       std::to_string(body.material) + ", not one of the scene's " +
                       std::to_string(scene.materials.size()) + " materials");
    model.body_names.push_back(body.name);
    model.body_fixed.push_back(body.fixed);
  }
  return model;
}

Model build_model(const Scene& scene, const std::vector<BodyMesh>& meshes, ElementOrder order) {
  FDEM_VERIFY(meshes.size() == scene.bodies.size(), "one mesh per body");
  Model model = model_frame(scene);
  // The whole model is local here: its counts must fit local indices (split bodies: 4 nodes a tet).
  std::size_t all_tets = 0, all_nodes = 0;
  for (std::size_t b = 0; b < meshes.size(); ++b) {
    const std::size_t tets = meshes[b].tets.size() / 4;
    all_tets += tets;
    all_nodes +=
        scene.bodies[b].joints == JointPlacement::all ? 4 * tets : meshes[b].coords.size() / 3;
  }
  local_count(all_tets, "tetrahedra");
  local_count(all_nodes, "nodes");

  // Gather every tet of every body with its body, piece and source position.
  struct TetRecord {
    std::int32_t body;
    LocalIndex local;  // index within its body mesh
    std::int32_t piece;
    std::uint64_t key;
  };
  std::vector<TetRecord> records;
  std::vector<LocalIndex> node_offset(meshes.size() + 1, 0);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (std::size_t b = 0; b < meshes.size(); ++b) {
    const BodyMesh& mesh = meshes[b];
    const LocalIndex n_nodes = static_cast<LocalIndex>(mesh.coords.size() / 3);
    node_offset[b + 1] = node_offset[b] + n_nodes;
    for (LocalIndex i = 0; i < n_nodes; ++i) {
      lo = lo.cwiseMin(vec3_at(mesh.coords.data(), i));
      hi = hi.cwiseMax(vec3_at(mesh.coords.data(), i));
    }
    std::int32_t n_pieces = 0;
    const auto piece = connected_pieces(mesh.tets, n_nodes, &n_pieces);
    const std::int32_t piece_base = static_cast<std::int32_t>(model.pieces.size());
    model.pieces.add_body(n_pieces);
    const LocalIndex n_tets = static_cast<LocalIndex>(mesh.tets.size() / 4);
    for (LocalIndex t = 0; t < n_tets; ++t) {
      Vec3 X[4];
      for (int c = 0; c < 4; ++c) X[c] = vec3_at(mesh.coords.data(), mesh.tets[4 * t + c]);
      check_tet_shape(X, scene.bodies[b].name, mesh.source,
                      mesh.source_tags.empty() ? t + 1 : mesh.source_tags[t]);
      records.push_back({static_cast<std::int32_t>(b), t, piece_base + piece[t], 0});
    }
  }
  if (records.empty()) throw InputError(scene.source_path + ": the scene has no tetrahedra");
  model.pieces.keep_all();

  // Element order: Morton keys of centroids give spatial locality in memory.
  if (order == ElementOrder::space_filling_curve) {
    for (auto& r : records) {
      const BodyMesh& mesh = meshes[r.body];
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += vec3_at(mesh.coords.data(), mesh.tets[4 * r.local + k]);
      r.key = morton_key(0.25 * c, lo, hi);
    }
    std::stable_sort(records.begin(), records.end(),
                     [](const TetRecord& a, const TetRecord& b) { return a.key < b.key; });
  }

  // Nodes get their ids in order of first use by the ordered tets.  In a body with
  // `joints: all` every tet owns its four nodes (the joints hold the copies together).
  const LocalIndex n_all_nodes = node_offset.back();
  std::vector<LocalIndex> new_node(n_all_nodes, -1);
  std::vector<LocalIndex> node_source;  // old (body-offset) node of each model node
  node_source.reserve(all_nodes);
  std::vector<LocalIndex> tet_node(4 * records.size());
  LocalIndex n_nodes = 0;
  for (std::size_t t = 0; t < records.size(); ++t) {
    const auto& r = records[t];
    const bool split = scene.bodies[r.body].joints == JointPlacement::all;
    for (int c = 0; c < 4; ++c) {
      const LocalIndex old = node_offset[r.body] + meshes[r.body].tets[4 * r.local + c];
      if (split) {
        tet_node[4 * t + c] = n_nodes++;
        node_source.push_back(old);
        continue;
      }
      if (new_node[old] < 0) {
        new_node[old] = n_nodes++;
        node_source.push_back(old);
      }
      tet_node[4 * t + c] = new_node[old];
    }
  }
  std::vector<std::int32_t> node_body(n_all_nodes);
  for (std::size_t b = 0; b < meshes.size(); ++b)
    for (LocalIndex i = node_offset[b]; i < node_offset[b + 1]; ++i)
      node_body[i] = static_cast<std::int32_t>(b);

  NodeArrays& nodes = model.nodes;
  nodes.has_prescribed_velocity = scene.prescribes_velocities();
  nodes.resize(n_nodes);
  nodes.n_owned = n_nodes;
  // Velocities and forces (48 B per node, most of a jointed body's start-up) are not read
  // before the joints are placed: they come after, so that the start-up's peak holds neither.
  release(nodes.v);
  release(nodes.f);
  std::fill(nodes.mass.begin(), nodes.mass.end(), 0.0);
  std::fill(nodes.constrained.begin(), nodes.constrained.end(), 0);
  std::fill(nodes.prescribed_velocity.begin(), nodes.prescribed_velocity.end(), 0.0);
  // One reference position per mesh node, shared by the nodes split from it.
  std::vector<std::int32_t> reference_of_mesh_node(static_cast<std::size_t>(n_all_nodes), -1);
  for (LocalIndex n = 0; n < n_nodes; ++n) {
    const LocalIndex old = node_source[n];
    std::int32_t& shared = reference_of_mesh_node[static_cast<std::size_t>(old)];
    if (shared < 0) {
      const std::int32_t b = node_body[old];
      nodes.add_reference(n, meshes[b].coords.data() + 3 * (old - node_offset[b]));
      shared = nodes.reference[n];
    } else {
      nodes.reference[n] = shared;
    }
    for (int k = 0; k < 3; ++k) nodes.x[3 * n + k] = nodes.x0(n)[k];
  }
  nodes.reference_positions.shrink_to_fit();
  release(node_source);
  release(reference_of_mesh_node);
  for (LocalIndex n = 0; n < n_nodes; ++n) nodes.gid[n] = model.gid_offset + n;

  TetArrays& tets = model.tets;
  const LocalIndex n_tets = static_cast<LocalIndex>(records.size());
  tets.resize(n_tets);
  tets.n_owned = n_tets;
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetRecord& r = records[t];
    const BodySpec& body = scene.bodies[r.body];
    const MaterialProperties& mat = model.materials[body.material];
    tets.gid[t] = model.gid_offset + t;
    tets.material[t] = body.material;
    tets.piece[t] = r.piece;
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tet_node[4 * t + c];
      tets.nodes[4 * t + c] = n;
      X[c] = nodes.x0(n);
      nodes.piece[n] = r.piece;
    }
    const TetSetup setup = setup_tet(X, mat);
    Eigen::Map<Mat3>(tets.dm_inv.data() + 9 * t) = setup.dm_inv;
    tets.volume0[t] = setup.volume;
    tets.viscosity[t] = setup.viscosity;
    for (int c = 0; c < 4; ++c) nodes.mass[tets.nodes[4 * t + c]] += 0.25 * setup.mass;
    add_to_piece(model.pieces[r.piece], setup.mass, X);
  }
  for (const std::int32_t piece : model.pieces.kept()) finish_piece(model.pieces[piece]);

  // Contact groups: a piece, or a single tet of a jointed body.
  tets.contact_group.resize(n_tets);
  std::int32_t next_group = static_cast<std::int32_t>(model.pieces.size());
  for (LocalIndex t = 0; t < n_tets; ++t)
    tets.contact_group[t] = scene.bodies[records[t].body].joints == JointPlacement::all
                                ? next_group++
                                : records[t].piece;
  set_dashpot_masses(model);

  std::vector<std::vector<LocalIndex>> model_tet(meshes.size());
  for (std::size_t b = 0; b < meshes.size(); ++b) model_tet[b].resize(meshes[b].tets.size() / 4);
  for (LocalIndex t = 0; t < n_tets; ++t) model_tet[records[t].body][records[t].local] = t;
  // The build's own tables go before the joints are placed (the start-up's peak is there).
  release(records);
  release(tet_node);
  release(new_node);
  release(node_body);
  place_joints(scene, meshes, model_tet, hi - lo, model);
  resize_exact(nodes.v, 3 * static_cast<std::size_t>(n_nodes), 0.0);
  resize_exact(nodes.f, 3 * static_cast<std::size_t>(n_nodes), 0.0);

  set_initial_velocities(scene, model);

  build_tet_force_order(tets, model.tet_force_order);
  apply_constraints(scene, model);
  // Corner contact reads them; a model whose bodies cannot meet has no contact stage.
  if (uses_corner_contact(scene) && contact_possible(model)) compute_contact_faces(model);
  return model;
}

std::int64_t owned_nodes_in_region(const RegionSpec& region, const NodeArrays& nodes) {
  std::int64_t count = 0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) count += in_region(region, nodes.x0(n)) ? 1 : 0;
  return count;
}

void apply_constraints(const Scene& scene, Model& model) {
  NodeArrays& nodes = model.nodes;
  FDEM_VERIFY(nodes.has_prescribed_velocity || !scene.prescribes_velocities(),
              "a scene with velocity loads keeps the prescribed velocities");
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    const std::int32_t body = model.pieces.body_of(nodes.piece[n]);
    if (scene.bodies[body].fixed) {
      nodes.constrained[n] = 7;
      if (nodes.has_prescribed_velocity) vec3_at(nodes.prescribed_velocity.data(), n).setZero();
      vec3_at(nodes.v.data(), n).setZero();
    }
  }
  for (const LoadSpec& load : scene.loads) {
    // Tilts, ramps and surface loads hold no node.
    if (!load.prescribes_velocity()) continue;
    // The velocity at t = 0 (drivers/loads sets it each step when it varies).
    const Vec3 velocity = load.kind == LoadSpec::Kind::velocity
                              ? Vec3(load.history(0.0) * load.velocity)
                              : load.velocity;
    for (LocalIndex n = 0; n < nodes.size(); ++n) {
      bool applies = false;
      if (load.region) {
        applies = in_region(*load.region, nodes.x0(n));
      } else {
        const std::int32_t body = model.pieces.body_of(nodes.piece[n]);
        applies = std::find(load.bodies.begin(), load.bodies.end(), body) != load.bodies.end();
      }
      if (!applies) continue;
      nodes.constrained[n] |= static_cast<std::uint8_t>(load.dof_mask);
      for (int k = 0; k < 3; ++k)
        if (load.dof_mask & (1u << k)) {
          nodes.prescribed_velocity[3 * n + k] = velocity[k];
          nodes.v[3 * n + k] = velocity[k];
        }
    }
  }
}

}  // namespace fdem
