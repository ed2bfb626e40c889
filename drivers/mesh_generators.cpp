#include "drivers/mesh_generators.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <sstream>

#include "core/checked_cast.hpp"
#include "core/error.hpp"
#include "core/tet_kernels.hpp"
#include "io/gmsh_reader.hpp"
#include "parallel/model_file.hpp"

namespace fdem {

BodyMesh box_mesh(const BoxMeshSpec& box) {
  const int nx = box.cells[0], ny = box.cells[1], nz = box.cells[2];
  BodyMesh mesh;
  mesh.source = "box generator";
  const Vec3 h = (box.max - box.min).cwiseQuotient(Vec3(nx, ny, nz));
  auto node = [&](int i, int j, int k) {
    return static_cast<LocalIndex>((k * (ny + 1) + j) * (nx + 1) + i);
  };
  mesh.coords.reserve(3 * (nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        // Exact end coordinates so touching boxes share their faces bit for bit.
        mesh.coords.push_back(i == nx ? box.max.x() : box.min.x() + i * h.x());
        mesh.coords.push_back(j == ny ? box.max.y() : box.min.y() + j * h.y());
        mesh.coords.push_back(k == nz ? box.max.z() : box.min.z() + k * h.z());
      }
  static const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                         {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& perm : permutations) {
          int corner[3] = {0, 0, 0};
          LocalIndex tet[4];
          tet[0] = node(i, j, k);
          for (int s = 0; s < 3; ++s) {
            corner[perm[s]] = 1;
            tet[s + 1] = node(i + corner[0], j + corner[1], k + corner[2]);
          }
          Vec3 X[4];
          for (int c = 0; c < 4; ++c) X[c] = vec3_at(mesh.coords.data(), tet[c]);
          if (tet_reference(X).volume < 0.0) std::swap(tet[2], tet[3]);
          mesh.tets.insert(mesh.tets.end(), tet, tet + 4);
        }
  return mesh;
}

BodyMesh mapped_box_mesh(const int cells[3],
                         const std::function<Vec3(double, double, double)>& map) {
  BoxMeshSpec unit;
  unit.min = Vec3::Zero();
  unit.max = Vec3::Ones();
  for (int k = 0; k < 3; ++k) unit.cells[k] = cells[k];
  BodyMesh mesh = box_mesh(unit);
  for (std::size_t n = 0; n < mesh.coords.size() / 3; ++n) {
    const Vec3 x = map(mesh.coords[3 * n], mesh.coords[3 * n + 1], mesh.coords[3 * n + 2]);
    for (int k = 0; k < 3; ++k) mesh.coords[3 * n + k] = x[k];
  }
  // A map may reverse orientation (a mirror, polar coordinates): restore positive volumes.
  for (std::size_t t = 0; t < mesh.tets.size() / 4; ++t) {
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) X[c] = vec3_at(mesh.coords.data(), mesh.tets[4 * t + c]);
    if (tet_reference(X).volume < 0.0) std::swap(mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
  }
  return mesh;
}

void append_piece(BodyMesh& mesh, const BodyMesh& piece) {
  const LocalIndex offset = static_cast<LocalIndex>(mesh.coords.size() / 3);
  mesh.coords.insert(mesh.coords.end(), piece.coords.begin(), piece.coords.end());
  for (LocalIndex n : piece.tets) mesh.tets.push_back(offset + n);
}

namespace {

BodyMesh unit_box(const Vec3& lo, const Vec3& size, int cx, int cy, int cz) {
  BoxMeshSpec box;
  box.min = lo;
  box.max = lo + size;
  box.cells[0] = cx;
  box.cells[1] = cy;
  box.cells[2] = cz;
  return box_mesh(box);
}

// One unit of a generated multi-unit mesh (a brick, a block, a voussoir): its box cells, which
// give its node and tet counts without making it, and how to make it.
struct MeshUnit {
  int cells[3];
  Vec3 centre;  // m, a point inside it
  Vec3 lo, hi;  // m, box of its corners
  std::function<BodyMesh()> make;
  std::int64_t n_nodes() const {
    return std::int64_t{cells[0] + 1} * (cells[1] + 1) * (cells[2] + 1);
  }
  std::int64_t n_tets() const { return std::int64_t{6} * cells[0] * cells[1] * cells[2]; }
};

MeshUnit box_unit(const Vec3& lo, const Vec3& size, int cx, int cy, int cz) {
  return {
      {cx, cy, cz}, lo + 0.5 * size, lo, lo + size, [=] { return unit_box(lo, size, cx, cy, cz); }};
}

MeshUnit mapped_unit(const int cells[3], std::function<Vec3(double, double, double)> map) {
  MeshUnit unit{{cells[0], cells[1], cells[2]}, map(0.5, 0.5, 0.5), map(0, 0, 0), map(0, 0, 0), {}};
  for (int corner = 1; corner < 8; ++corner) {
    const Vec3 x = map(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    unit.lo = unit.lo.cwiseMin(x);
    unit.hi = unit.hi.cwiseMax(x);
  }
  const int c[3] = {cells[0], cells[1], cells[2]};
  unit.make = [c0 = c[0], c1 = c[1], c2 = c[2], map = std::move(map)] {
    const int n[3] = {c0, c1, c2};
    return mapped_box_mesh(n, map);
  };
  return unit;
}

std::vector<MeshUnit> wall_units(const WallMeshSpec& wall) {
  const double lx = wall.unit.x(), g = wall.mortar_gap;
  const int n = wall.units_per_course;
  const bool running = wall.bond == WallMeshSpec::Bond::running;
  if (!(wall.unit.minCoeff() > 0.0) || wall.courses < 1 || n < 1 || g < 0.0 ||
      (running && (!(g < lx) || wall.cells[0] % 2 != 0)))
    throw InputError(
        "wall generator: needs unit sizes > 0, courses >= 1, units per course >= 1, "
        "0 <= mortar gap (< unit length for running bond) and an even cells[0] for running bond");
  std::vector<MeshUnit> units;
  const Vec3 size = wall.unit;
  const Vec3 half(0.5 * (lx - g), size.y(), size.z());
  const int* c = wall.cells;
  for (int course = 0; course < wall.courses; ++course) {
    const double z = wall.origin.z() + course * (size.z() + g);
    const Vec3 start(wall.origin.x(), wall.origin.y(), z);
    if (!running || course % 2 == 0) {
      for (int i = 0; i < n; ++i)
        units.push_back(box_unit(start + Vec3(i * (lx + g), 0, 0), size, c[0], c[1], c[2]));
      continue;
    }
    // Running bond: alternate courses start and end with a half unit (joints offset by half).
    const int half_cells = c[0] / 2;
    units.push_back(box_unit(start, half, half_cells, c[1], c[2]));
    const double first = half.x() + g;
    for (int i = 0; i + 1 < n; ++i)
      units.push_back(box_unit(start + Vec3(first + i * (lx + g), 0, 0), size, c[0], c[1], c[2]));
    units.push_back(
        box_unit(start + Vec3(first + (n - 1) * (lx + g), 0, 0), half, half_cells, c[1], c[2]));
  }
  return units;
}

std::vector<MeshUnit> tower_units(const TowerMeshSpec& tower) {
  if (!(tower.block.minCoeff() > 0.0) || tower.blocks < 1)
    throw InputError("tower generator: needs block sizes > 0 and blocks >= 1");
  std::vector<MeshUnit> units;
  for (int i = 0; i < tower.blocks; ++i)
    units.push_back(box_unit(tower.origin + Vec3(0, 0, i * tower.block.z()), tower.block,
                             tower.cells[0], tower.cells[1], tower.cells[2]));
  return units;
}

std::vector<MeshUnit> arch_units(const ArchMeshSpec& arch) {
  const double R = arch.radius, t = arch.thickness, alpha = arch.half_angle;
  const int n = arch.voussoirs;
  if (!(R > 0.0) || !(t > 0.0) || !(arch.depth > 0.0) || n < 1 || !(alpha > 0.0) ||
      alpha > 0.5 * M_PI + 1e-12 ||
      (arch.abutments && (!(arch.abutment_width > 0.0) || !(arch.abutment_height > 0.0))))
    throw InputError(
        "arch generator: needs radius, thickness, depth > 0, voussoirs >= 1, a half angle in (0, "
        "90] degrees and abutment width and height > 0");
  const Vec3 o = arch.origin;
  const double depth = arch.depth;
  // Joint angles from the right springing (π/2 − α) to the left one (π/2 + α), one table so
  // both voussoirs at a joint use the same angle.
  std::vector<double> theta(n + 1);
  for (int k = 0; k <= n; ++k) theta[k] = 0.5 * M_PI - alpha + 2.0 * alpha * k / n;
  std::vector<MeshUnit> units;
  for (int k = 0; k < n; ++k) {
    const double a = theta[k], b = theta[k + 1];
    units.push_back(mapped_unit(arch.cells, [=](double u, double v, double w) {
      const double r = R + u * t, angle = (1.0 - v) * a + v * b;
      return Vec3(o.x() + r * std::cos(angle), o.y() + w * depth, o.z() + r * std::sin(angle));
    }));
  }
  if (arch.abutments) {
    // Under each springing a four-sided block (extruded along y): its top is the springing face
    // (same cells, so it conforms), its foot is horizontal, `height` below the inner corner.
    const double c = std::cos(theta[0]), s = std::sin(theta[0]);
    const double size = t / arch.cells[0];
    const auto high = to_integer<int>(std::max(1.0, std::round(arch.abutment_height / size)));
    if (!high)
      throw InputError("arch generator: abutments " + std::to_string(arch.abutment_height) +
                       " m high need more cells than a mesh can have");
    const int cells[3] = {arch.cells[0], *high, arch.cells[2]};
    for (double side : {1.0, -1.0}) {
      const auto at = [&](double x_rel, double z_rel) {  // mirror x about the arch's axis
        return Eigen::Vector2d(o.x() + side * x_rel, o.z() + z_rel);
      };
      const Eigen::Vector2d top_in = at(R * c, R * s), top_out = at((R + t) * c, (R + t) * s);
      const Eigen::Vector2d foot_in = at(R * c, R * s - arch.abutment_height);
      const Eigen::Vector2d foot_out =
          at(R * c + arch.abutment_width, R * s - arch.abutment_height);
      units.push_back(mapped_unit(cells, [=](double u, double v, double w) {
        const Eigen::Vector2d p =
            (1 - v) * ((1 - u) * foot_in + u * foot_out) + v * ((1 - u) * top_in + u * top_out);
        return Vec3(p.x(), o.y() + w * depth, p.y());
      }));
    }
  }
  return units;
}

BodyMesh join_units(const std::vector<MeshUnit>& units, std::string source) {
  BodyMesh mesh;
  for (const MeshUnit& unit : units) append_piece(mesh, unit.make());
  mesh.source = std::move(source);
  return mesh;
}

std::string wall_source(const WallMeshSpec& wall) {
  const bool running = wall.bond == WallMeshSpec::Bond::running;
  return std::string(running ? "running" : "stack") + " bond wall generator";
}

// Units as chunks: unit u is piece u, its nodes and tets follow those of the units before it.
BodyChunks unit_chunks(std::vector<MeshUnit> units, std::string source) {
  BodyChunks chunks;
  chunks.source = std::move(source);
  auto node_offset = std::make_shared<std::vector<std::int64_t>>();
  auto tet_offset = std::make_shared<std::vector<std::int64_t>>();
  std::int64_t tets = 0;
  chunks.lo = Vec3::Constant(1e300);
  chunks.hi = Vec3::Constant(-1e300);
  for (const MeshUnit& unit : units) {
    chunks.lo = chunks.lo.cwiseMin(unit.lo);
    chunks.hi = chunks.hi.cwiseMax(unit.hi);
    node_offset->push_back(chunks.n_nodes);
    tet_offset->push_back(tets);
    chunks.n_nodes += unit.n_nodes();
    tets += unit.n_tets();
    chunks.chunk_tets.push_back(unit.n_tets());
    chunks.chunk_centre.push_back(unit.centre);
  }
  chunks.n_pieces = static_cast<std::int32_t>(units.size());
  auto shared_units = std::make_shared<std::vector<MeshUnit>>(std::move(units));
  chunks.generate = [shared_units, node_offset, tet_offset](std::int64_t u) {
    const auto i = static_cast<std::size_t>(u);
    MeshChunk chunk;
    chunk.mesh = (*shared_units)[i].make();
    chunk.node_id.resize(chunk.mesh.coords.size() / 3);
    std::iota(chunk.node_id.begin(), chunk.node_id.end(), (*node_offset)[i]);
    chunk.tet_id.resize(chunk.mesh.tets.size() / 4);
    std::iota(chunk.tet_id.begin(), chunk.tet_id.end(), (*tet_offset)[i]);
    chunk.piece = static_cast<std::int32_t>(u);
    return chunk;
  };
  return chunks;
}

// One block of up to block_cells³ cells of a box (blocks numbered x fastest): its nodes numbered
// as box_mesh numbers them, its tets with their box_mesh numbers and corners.
MeshChunk box_block(const BoxMeshSpec& box, int block_cells, std::int64_t block) {
  const auto blocks_along = [&](int cells) { return (cells + block_cells - 1) / block_cells; };
  const int nx = box.cells[0], ny = box.cells[1], nz = box.cells[2];
  const std::int64_t bx = blocks_along(nx), by = blocks_along(ny);
  const int i0 = static_cast<int>(block % bx) * block_cells;
  const int j0 = static_cast<int>(block / bx % by) * block_cells;
  const int k0 = static_cast<int>(block / (bx * by)) * block_cells;
  const int i1 = std::min(nx, i0 + block_cells), j1 = std::min(ny, j0 + block_cells),
            k1 = std::min(nz, k0 + block_cells);
  const Vec3 h = (box.max - box.min).cwiseQuotient(Vec3(nx, ny, nz));
  MeshChunk chunk;
  chunk.mesh.source = "box generator";
  const int sx = i1 - i0 + 1, sy = j1 - j0 + 1;
  const auto local = [&](int i, int j, int k) {
    return static_cast<LocalIndex>(((k - k0) * sy + (j - j0)) * sx + (i - i0));
  };
  for (int k = k0; k <= k1; ++k)
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        // The same expressions as box_mesh: nodes shared with other blocks match bit for bit.
        chunk.mesh.coords.push_back(i == nx ? box.max.x() : box.min.x() + i * h.x());
        chunk.mesh.coords.push_back(j == ny ? box.max.y() : box.min.y() + j * h.y());
        chunk.mesh.coords.push_back(k == nz ? box.max.z() : box.min.z() + k * h.z());
        chunk.node_id.push_back((std::int64_t{k} * (ny + 1) + j) * (nx + 1) + i);
      }
  static const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                         {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = k0; k < k1; ++k)
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i)
        for (int p = 0; p < 6; ++p) {
          int corner[3] = {0, 0, 0};
          LocalIndex tet[4];
          tet[0] = local(i, j, k);
          for (int s = 0; s < 3; ++s) {
            corner[permutations[p][s]] = 1;
            tet[s + 1] = local(i + corner[0], j + corner[1], k + corner[2]);
          }
          Vec3 X[4];
          for (int c = 0; c < 4; ++c) X[c] = vec3_at(chunk.mesh.coords.data(), tet[c]);
          if (tet_reference(X).volume < 0.0) std::swap(tet[2], tet[3]);
          chunk.mesh.tets.insert(chunk.mesh.tets.end(), tet, tet + 4);
          chunk.tet_id.push_back(((std::int64_t{k} * ny + j) * nx + i) * 6 + p);
        }
  return chunk;
}

}  // namespace

BodyMesh wall_mesh(const WallMeshSpec& wall) {
  return join_units(wall_units(wall), wall_source(wall));
}

BodyMesh tower_mesh(const TowerMeshSpec& tower) {
  return join_units(tower_units(tower), "tower generator");
}

BodyMesh arch_mesh(const ArchMeshSpec& arch) {
  return join_units(arch_units(arch), "arch generator");
}

BodyChunks body_chunks(const MeshSpec& mesh, int ranks) {
  switch (mesh.kind) {
    case MeshSpec::Kind::box: {
      const BoxMeshSpec box = mesh.box;
      const int nx = box.cells[0], ny = box.cells[1], nz = box.cells[2];
      // Blocks of b³ cells, b in [2, 8], about 64 per rank.
      const double cells_per_chunk = double(nx) * ny * nz / (64.0 * std::max(ranks, 1));
      const int block_cells = std::clamp(static_cast<int>(std::cbrt(cells_per_chunk)), 2, 8);
      BodyChunks chunks;
      chunks.source = "box generator";
      chunks.lo = box.min;
      chunks.hi = box.max;
      chunks.n_nodes = std::int64_t{nx + 1} * (ny + 1) * (nz + 1);
      chunks.n_pieces = 1;
      const Vec3 h = (box.max - box.min).cwiseQuotient(Vec3(nx, ny, nz));
      for (int k = 0; k < nz; k += block_cells)
        for (int j = 0; j < ny; j += block_cells)
          for (int i = 0; i < nx; i += block_cells) {
            const int cx = std::min(block_cells, nx - i), cy = std::min(block_cells, ny - j),
                      cz = std::min(block_cells, nz - k);
            chunks.chunk_tets.push_back(std::int64_t{6} * cx * cy * cz);
            chunks.chunk_centre.push_back(
                box.min + h.cwiseProduct(Vec3(i + 0.5 * cx, j + 0.5 * cy, k + 0.5 * cz)));
          }
      chunks.generate = [box, block_cells](std::int64_t block) {
        return box_block(box, block_cells, block);
      };
      return chunks;
    }
    case MeshSpec::Kind::wall:
      return unit_chunks(wall_units(mesh.wall), wall_source(mesh.wall));
    case MeshSpec::Kind::tower:
      return unit_chunks(tower_units(mesh.tower), "tower generator");
    case MeshSpec::Kind::arch:
      return unit_chunks(arch_units(mesh.arch), "arch generator");
    case MeshSpec::Kind::file:
      break;
  }
  throw InputError("mesh file '" + mesh.file + "' has no chunked form");
}

std::string mesh_source(const MeshSpec& mesh) {
  return mesh.file + (mesh.physical.empty() ? "" : " [" + mesh.physical + "]");
}

std::vector<BodyMesh> load_body_meshes(const Scene& scene) {
  std::vector<BodyMesh> meshes;
  for (const BodySpec& body : scene.bodies) {
    if (body.mesh.kind == MeshSpec::Kind::box) {
      meshes.push_back(box_mesh(body.mesh.box));
    } else if (body.mesh.kind == MeshSpec::Kind::wall) {
      meshes.push_back(wall_mesh(body.mesh.wall));
    } else if (body.mesh.kind == MeshSpec::Kind::arch) {
      meshes.push_back(arch_mesh(body.mesh.arch));
    } else if (body.mesh.kind == MeshSpec::Kind::tower) {
      meshes.push_back(tower_mesh(body.mesh.tower));
    } else {
      // A model file (fdem prepare) gives the mesh of the .msh it was prepared from.
      const GmshMesh g = is_hdf5_file(body.mesh.file)
                             ? read_model_file(body.mesh.file, body.mesh.physical)
                             : read_gmsh(body.mesh.file, body.mesh.physical);
      BodyMesh mesh;
      mesh.source = mesh_source(body.mesh);
      mesh.coords = g.coords;
      mesh.tets.assign(g.tets.begin(), g.tets.end());
      mesh.source_tags.assign(g.tet_tags.begin(), g.tet_tags.end());
      meshes.push_back(std::move(mesh));
    }
  }
  return meshes;
}

}  // namespace fdem
