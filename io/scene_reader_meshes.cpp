// Scene keys of a body's mesh: `mesh:` as a box, a Gmsh file, or one of the masonry generators
// (`wall`, `arch`, `tower`).  docs/scene-format.md, "Bodies".
#include <filesystem>
#include <string>

#include "core/checked_cast.hpp"
#include "io/scene_reader_support.hpp"

namespace fdem::scene_reading {
namespace {

// [nx, ny, nz] positive integers (cells per generated unit).
void read_cells(const Reader& r, const YAML::Node& cells, const std::string& path, int out[3]) {
  r.require_present(cells, path, "three positive integers [nx, ny, nz]");
  if (!cells.IsSequence() || cells.size() != 3)
    r.fail(cells, path, "expected three integers [nx, ny, nz]");
  for (int k = 0; k < 3; ++k) {
    out[k] = r.integer(cells[k], path);
    if (out[k] < 1) r.fail(cells[k], path, "each cell count must be >= 1");
  }
}

// Three positive sizes [x, y, z] (m).
Vec3 read_size(const Reader& r, const YAML::Node& node, const std::string& path) {
  const Vec3 size = r.vec3(node, path);
  if (!(size.minCoeff() > 0.0)) r.fail(node, path, "each size must be > 0 (m)");
  return size;
}

int positive_count(const Reader& r, const YAML::Node& node, const std::string& path,
                   const std::string& what) {
  const int n = r.integer(node, path);
  if (n < 1) r.fail(node, path, std::to_string(n) + " is impossible: " + what + " must be >= 1");
  return n;
}

WallMeshSpec read_wall(const Reader& r, const YAML::Node& w, const std::string& path) {
  r.check_keys(w, path,
               {"unit", "courses", "length", "units_per_course", "bond", "mortar_gap",
                "cells_per_unit", "origin"},
               {"unit", "courses"});
  WallMeshSpec wall;
  wall.unit = read_size(r, w["unit"], path + ".unit");
  wall.courses = positive_count(r, w["courses"], path + ".courses", "the number of courses");
  if (w["bond"])
    wall.bond = r.choice(w["bond"], path + ".bond", {"stack", "running"}) == "running"
                    ? WallMeshSpec::Bond::running
                    : WallMeshSpec::Bond::stack;
  if (w["mortar_gap"])
    wall.mortar_gap = r.non_negative(w["mortar_gap"], path + ".mortar_gap", "mortar gap (m)");
  const double lx = wall.unit.x(), g = wall.mortar_gap;
  if (wall.bond == WallMeshSpec::Bond::running && !(g < lx))
    r.fail(w["mortar_gap"], path + ".mortar_gap",
           "must be smaller than the unit length " + Reader::format(lx) +
               " m (running bond has half units of (length - gap)/2)");
  if (w["length"] && w["units_per_course"])
    r.fail(w, path, "give either 'length' or 'units_per_course', not both");
  if (w["units_per_course"]) {
    wall.units_per_course = positive_count(r, w["units_per_course"], path + ".units_per_course",
                                           "the number of units per course");
  } else if (w["length"]) {
    const double length = r.positive(w["length"], path + ".length", "wall length (m)");
    // n units and n − 1 gaps make the length.
    const double units = std::max(1.0, std::round((length + g) / (lx + g)));
    if (!fits_integer<int>(units))
      r.fail(w["length"], path + ".length",
             Reader::format(length) + " m is " + Reader::format(units) + " units of " +
                 Reader::format(lx) + " m: more than a wall can have");
    const long n = static_cast<long>(units);
    const double made = n * lx + (n - 1) * g;
    if (std::abs(made - length) > 1e-6 * length) {
      const double below = (n > 1 ? n - 1 : 1) * lx + (n > 1 ? n - 2 : 0) * g;
      r.fail(w["length"], path + ".length",
             Reader::format(length) + " m is not a whole number of units of " + Reader::format(lx) +
                 " m with gaps of " + Reader::format(g) + " m: " + std::to_string(n) +
                 " units make " + Reader::format(made) + " m" +
                 (n > 1 ? ", " + std::to_string(n - 1) + " make " + Reader::format(below) + " m"
                        : std::string()) +
                 ". Give one of these lengths or units_per_course.");
    }
    wall.units_per_course = static_cast<int>(n);
  } else {
    r.fail(w, path + ".length", "missing 'length' (m) or 'units_per_course'");
  }
  if (w["cells_per_unit"]) read_cells(r, w["cells_per_unit"], path + ".cells_per_unit", wall.cells);
  if (wall.bond == WallMeshSpec::Bond::running && wall.cells[0] % 2 != 0)
    r.fail(w["cells_per_unit"], path + ".cells_per_unit",
           "the first count (cells along the unit) must be even for running bond, so the "
           "half-unit offset falls on a mesh line and touching units share their triangles");
  if (w["origin"]) wall.origin = r.vec3(w["origin"], path + ".origin");
  return wall;
}

ArchMeshSpec read_arch(const Reader& r, const YAML::Node& a, const std::string& path) {
  r.check_keys(a, path,
               {"kind", "radius", "thickness", "depth", "voussoirs", "rise", "angle", "abutments",
                "cells_per_voussoir", "origin"},
               {"radius", "thickness", "depth", "voussoirs"});
  ArchMeshSpec arch;
  if (a["kind"])
    arch.kind = r.choice(a["kind"], path + ".kind", {"semicircular", "segmental"}) == "segmental"
                    ? ArchMeshSpec::Kind::segmental
                    : ArchMeshSpec::Kind::semicircular;
  arch.radius = r.positive(a["radius"], path + ".radius", "intrados radius (m)");
  arch.thickness = r.positive(a["thickness"], path + ".thickness", "arch thickness (m)");
  arch.depth = r.positive(a["depth"], path + ".depth", "arch depth (m)");
  arch.voussoirs =
      positive_count(r, a["voussoirs"], path + ".voussoirs", "the number of voussoirs");
  if (arch.kind == ArchMeshSpec::Kind::semicircular) {
    for (const char* key : {"rise", "angle"})
      if (a[key])
        r.fail(a[key], path + "." + key,
               std::string("'") + key +
                   "' applies to kind: segmental only (a semicircular arch "
                   "subtends 180 degrees)");
    arch.half_angle = 0.5 * M_PI;
  } else {
    if (a["rise"] && a["angle"]) r.fail(a, path, "give either 'rise' or 'angle', not both");
    if (a["rise"]) {
      const double rise = r.positive(a["rise"], path + ".rise", "rise of the intrados (m)");
      if (!(rise < arch.radius))
        r.fail(a["rise"], path + ".rise",
               Reader::format(rise) +
                   " m is impossible: a segmental arch's rise must be below "
                   "the radius " +
                   Reader::format(arch.radius) + " m (rise = radius is kind: semicircular)");
      arch.half_angle = std::acos(1.0 - rise / arch.radius);
    } else if (a["angle"]) {
      const double angle = r.number(a["angle"], path + ".angle");
      if (!(angle > 0.0 && angle < 180.0))
        r.fail(a["angle"], path + ".angle",
               Reader::format(angle) +
                   " is impossible: the angle the arch subtends is in degrees, 0 < angle < 180");
      arch.half_angle = 0.5 * angle * M_PI / 180.0;
    } else {
      r.fail(a, path + ".rise", "a segmental arch needs 'rise' (m) or 'angle' (degrees)");
    }
  }
  if (const YAML::Node ab = a["abutments"]) {
    const std::string ap = path + ".abutments";
    r.check_keys(ab, ap, {"width", "height"}, {"width", "height"});
    arch.abutments = true;
    arch.abutment_width = r.positive(ab["width"], ap + ".width", "abutment width (m)");
    arch.abutment_height = r.positive(ab["height"], ap + ".height", "abutment height (m)");
  }
  if (a["cells_per_voussoir"])
    read_cells(r, a["cells_per_voussoir"], path + ".cells_per_voussoir", arch.cells);
  if (a["origin"]) arch.origin = r.vec3(a["origin"], path + ".origin");
  return arch;
}

TowerMeshSpec read_tower(const Reader& r, const YAML::Node& t, const std::string& path) {
  r.check_keys(t, path, {"block", "blocks", "cells_per_block", "origin"}, {"block", "blocks"});
  TowerMeshSpec tower;
  tower.block = read_size(r, t["block"], path + ".block");
  tower.blocks = positive_count(r, t["blocks"], path + ".blocks", "the number of blocks");
  if (t["cells_per_block"])
    read_cells(r, t["cells_per_block"], path + ".cells_per_block", tower.cells);
  if (t["origin"]) tower.origin = r.vec3(t["origin"], path + ".origin");
  return tower;
}

}  // namespace

MeshSpec read_mesh(const Reader& r, const YAML::Node& node, const std::string& path,
                   const std::string& scene_dir) {
  r.check_keys(node, path, {"box", "file", "physical", "wall", "arch", "tower"});
  MeshSpec mesh;
  int kinds = 0;
  for (const char* key : {"box", "file", "wall", "arch", "tower"}) kinds += node[key] ? 1 : 0;
  if (node["box"] && node["file"]) r.fail(node, path, "give either 'box' or 'file', not both");
  if (kinds > 1) r.fail(node, path, "give one of box, file, wall, arch, tower, not several");
  if (node["physical"] && !node["file"])
    r.fail(node["physical"], path + ".physical", "'physical' applies to 'file' meshes only");
  if (node["wall"]) {
    mesh.kind = MeshSpec::Kind::wall;
    mesh.wall = read_wall(r, node["wall"], path + ".wall");
  } else if (node["arch"]) {
    mesh.kind = MeshSpec::Kind::arch;
    mesh.arch = read_arch(r, node["arch"], path + ".arch");
  } else if (node["tower"]) {
    mesh.kind = MeshSpec::Kind::tower;
    mesh.tower = read_tower(r, node["tower"], path + ".tower");
  } else if (const YAML::Node b = node["box"]) {
    const std::string bp = path + ".box";
    r.check_keys(b, bp, {"min", "max", "cells"}, {"min", "max"});
    mesh.kind = MeshSpec::Kind::box;
    mesh.box.min = r.vec3(b["min"], bp + ".min");
    mesh.box.max = r.vec3(b["max"], bp + ".max");
    for (int k = 0; k < 3; ++k)
      if (!(mesh.box.max[k] > mesh.box.min[k]))
        r.fail(b["max"], bp + ".max", "each component of max must be larger than min's");
    if (const YAML::Node cells = b["cells"]) {
      if (!cells.IsSequence() || cells.size() != 3)
        r.fail(cells, bp + ".cells", "expected three integers [nx, ny, nz]");
      for (int k = 0; k < 3; ++k) {
        mesh.box.cells[k] = r.integer(cells[k], bp + ".cells");
        if (mesh.box.cells[k] < 1) r.fail(cells[k], bp + ".cells", "each cell count must be >= 1");
      }
    }
    if (node["physical"])
      r.fail(node["physical"], path + ".physical", "'physical' applies to 'file' meshes only");
  } else if (const YAML::Node f = node["file"]) {
    mesh.kind = MeshSpec::Kind::file;
    const std::filesystem::path p(r.string(f, path + ".file"));
    mesh.file = p.is_absolute()
                    ? p.string()
                    : (std::filesystem::path(scene_dir) / p).lexically_normal().string();
    if (!std::filesystem::exists(mesh.file))
      r.fail(f, path + ".file",
             "mesh file '" + mesh.file + "' does not exist (paths are relative to the scene file)");
    if (node["physical"]) mesh.physical = r.string(node["physical"], path + ".physical");
  } else {
    r.fail(node, path, "a mesh needs one of: box, file, wall, arch, tower");
  }
  return mesh;
}

}  // namespace fdem::scene_reading
