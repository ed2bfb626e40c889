#include "drivers/run_limits.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/checked_cast.hpp"
#include "core/error.hpp"

namespace fdem {

namespace {

// Peak bytes per entity of a run on one rank, fitted above the peak RSS of runs measured with
// /usr/bin/time (Release, 1 rank, a few steps with output): 384 000 tets of one box 157 MB
// (estimate 234 MB), two touching boxes of 324 000 tets with contact 193 MB (204 MB), 48 000 tets
// with 93 600 joints 159 MB (185 MB).  The base covers MPI, VTK and HDF5.
constexpr double bytes_per_tet = 450.0;
constexpr double bytes_per_node = 300.0;
constexpr double bytes_per_joint = 700.0;
constexpr double base_bytes = 40e6;

// A generated unit of c[0]·c[1]·c[2] cells: 6 tets per cell, its own nodes.
ModelSize unit_size(const int cells[3], double units) {
  const double c0 = cells[0], c1 = cells[1], c2 = cells[2];
  return {units * (c0 + 1) * (c1 + 1) * (c2 + 1), units * 6.0 * c0 * c1 * c2, 0.0};
}

ModelSize add(ModelSize a, const ModelSize& b) {
  a.nodes += b.nodes;
  a.tets += b.tets;
  a.joints += b.joints;
  return a;
}

ModelSize body_size(const BodySpec& body) {
  const MeshSpec& mesh = body.mesh;
  ModelSize size;
  switch (mesh.kind) {
    case MeshSpec::Kind::box:
      size = unit_size(mesh.box.cells, 1.0);
      break;
    case MeshSpec::Kind::wall: {
      // Running bond: n − 1 full and 2 half units in every other course; n + 1 units bound it.
      const double units = double(mesh.wall.courses) * (double(mesh.wall.units_per_course) + 1.0);
      size = unit_size(mesh.wall.cells, units);
      break;
    }
    case MeshSpec::Kind::arch: {
      const ArchMeshSpec& arch = mesh.arch;
      size = unit_size(arch.cells, arch.voussoirs);
      if (arch.abutments) {  // two blocks, height / (thickness / cells[0]) cells high
        const double high =
            std::max(1.0, std::round(arch.abutment_height * arch.cells[0] / arch.thickness));
        const double c0 = arch.cells[0], c2 = arch.cells[2];
        size = add(size, {2.0 * (c0 + 1) * (high + 1) * (c2 + 1), 2.0 * 6.0 * c0 * high * c2, 0});
      }
      break;
    }
    case MeshSpec::Kind::tower:
      size = unit_size(mesh.tower.cells, mesh.tower.blocks);
      break;
    case MeshSpec::Kind::file:
      return size;  // checked on the model, once read
  }
  // A tet has 4 faces, an interior one is shared by two tets: at most 2 joints per tet.
  if (body.joints == JointPlacement::all) size.joints = 2.0 * size.tets;
  if (body.joints == JointPlacement::interfaces) size.joints = size.tets;
  return size;
}

// The memory limit of this process's cgroup (v2, then v1), or infinity.
double cgroup_memory_limit() {
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    double bytes = 0.0;
    if (in >> bytes && bytes > 0.0) return bytes;  // "max" fails to parse: no limit
  }
  return std::numeric_limits<double>::infinity();
}

double resource_limit(int resource) {
  rlimit limit{};
  if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
    return std::numeric_limits<double>::infinity();
  return static_cast<double>(limit.rlim_cur);
}

std::string format_count(double value) {
  std::ostringstream out;
  if (fits_integer<long>(value) && value < 1e15)
    out << static_cast<long>(value);
  else
    out << value;
  return out.str();
}

}  // namespace

std::string format_bytes(double bytes) {
  std::ostringstream out;
  out.precision(3);
  if (bytes >= 1e9)
    out << bytes / 1e9 << " GB";
  else if (bytes >= 1e6)
    out << bytes / 1e6 << " MB";
  else
    out << bytes << " bytes";
  return out.str();
}

ModelSize estimate_generated_size(const Scene& scene) {
  ModelSize total;
  for (const BodySpec& body : scene.bodies) total = add(total, body_size(body));
  return total;
}

ModelSize model_size(const Model& model) {
  return {double(model.nodes.size()), double(model.tets.size()), double(model.joints.size())};
}

double estimated_bytes_per_rank(const ModelSize& size, int ranks, bool distributed_start) {
  const double model =
      bytes_per_tet * size.tets + bytes_per_node * size.nodes + bytes_per_joint * size.joints;
  // N ranks: the whole model and this rank's part (with its halo) exist together at the start;
  // a distributed start holds only the part, with its sort buffers and halo (≤ 2.5 parts).
  const double share = ranks == 1 ? 1.0 : distributed_start ? 2.5 / ranks : 1.0 + 1.5 / ranks;
  return base_bytes + model * share;
}

double memory_ceiling_per_rank(const LimitsSpec& limits, int ranks_on_node, std::string* source) {
  if (limits.max_memory_per_rank > 0.0) {
    if (source) *source = "limits.max_memory_per_rank";
    return limits.max_memory_per_rank;
  }
  const double physical = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  const double cgroup = cgroup_memory_limit();
  const double node = std::min(physical > 0 ? physical : cgroup, cgroup);
  const double per_rank = node / std::max(1, ranks_on_node);
  const double process = std::min(resource_limit(RLIMIT_AS), resource_limit(RLIMIT_DATA));
  if (source) {
    std::ostringstream why;
    if (process < per_rank)
      why << "automatic: this process's ulimit -v/-d of " << format_bytes(process);
    else
      why << "automatic: " << (cgroup < physical ? "the cgroup memory limit " : "the memory ")
          << format_bytes(node) << " of this node shared by " << std::max(1, ranks_on_node)
          << " rank(s)";
    *source = why.str();
  }
  return std::min(per_rank, process);
}

namespace {

// A rank that would hold more nodes, tets or joints than max_local_entries (core/types.hpp:
// 32-bit local indices) cannot run whatever its memory: its part with a distributed start, else
// the whole model, which every rank builds.
void check_local_counts(const Scene& scene, const ModelSize& size, int ranks,
                        bool distributed_start, const std::string& what) {
  const double local_share = ranks > 1 && distributed_start ? 2.5 / ranks : 1.0;
  const double most = std::max({size.tets, size.nodes, size.joints}) * local_share;
  if (most <= static_cast<double>(max_local_entries)) return;
  std::ostringstream msg;
  msg << scene.source_path << ": " << what << " would put about " << format_count(most)
      << " nodes, tetrahedra or joints on one rank (" << format_count(size.tets) << " tetrahedra, "
      << format_count(size.nodes) << " nodes in all), more than the " << max_local_entries
      << " one rank can index (32-bit local indices). Run on more ranks"
      << (distributed_start ? "." : " with parallel.distributed_start: true.");
  throw InputError(msg.str());
}

}  // namespace

void check_memory_limit(const Scene& scene, const ModelSize& size, int ranks, int ranks_on_node,
                        bool distributed_start, const std::string& what) {
  std::string source;
  const double ceiling = memory_ceiling_per_rank(scene.limits, ranks_on_node, &source);
  const double needed = estimated_bytes_per_rank(size, ranks, distributed_start);
  if (needed <= ceiling) {
    check_local_counts(scene, size, ranks, distributed_start, what);
    return;
  }
  std::ostringstream msg;
  msg << scene.source_path << ": " << what << " would need about " << format_bytes(needed)
      << " per rank (" << format_count(size.tets) << " tetrahedra, " << format_count(size.nodes)
      << " nodes";
  if (size.joints > 0) msg << ", up to " << format_count(size.joints) << " joints";
  msg << "), more than limits.max_memory_per_rank = " << format_bytes(ceiling) << " (" << source
      << "). Use fewer cells (mesh cells, cells_per_unit, courses, blocks), more ranks on more "
         "nodes, or set limits.max_memory_per_rank (bytes) if the machine has more.";
  throw InputError(msg.str());
}

double step_count(double start, double end, double dt) {
  return std::ceil((end - start) / dt - 1e-9);
}

void check_step_limit(const Scene& scene, double start, double dt,
                      const std::function<std::string()>& step_origin) {
  const double steps = step_count(start, scene.time.end, dt);
  if (steps <= scene.limits.max_steps && fits_integer<long>(steps)) return;
  std::ostringstream msg;
  msg.precision(4);
  msg << scene.source_path << ": this run needs " << format_count(steps) << " time steps ("
      << "time.end " << scene.time.end << " s";
  if (start > 0) msg << " from t = " << start << " s";
  msg << " with a step of " << dt
      << " s), more than limits.max_steps = " << format_count(scene.limits.max_steps) << ". "
      << step_origin()
      << " Shorten time.end, fix the mesh or stiffness that sets the step, or raise "
         "limits.max_steps if this many steps are intended.";
  throw InputError(msg.str());
}

long checked_step_count(double start, double end, double dt) {
  const double steps = std::max(0.0, step_count(start, end, dt));
  const auto count = to_integer<long>(steps);
  FDEM_VERIFY(count.has_value(), "step count " + std::to_string(steps) + " was not checked");
  return *count;
}

std::string describe_tet(const Model& model, LocalIndex tet) {
  if (tet < 0 || tet >= model.tets.size()) return "an element";
  const LocalIndex* n = &model.tets.nodes[4 * static_cast<std::size_t>(tet)];
  const double* x = model.nodes.x.data();
  // Smallest height = 3 V / largest face area (m), of the current shape.
  const Vec3 x0 = vec3_at(x, n[0]);
  const double volume =
      std::abs((vec3_at(x, n[1]) - x0).dot((vec3_at(x, n[2]) - x0).cross(vec3_at(x, n[3]) - x0))) /
      6.0;
  double largest_area = 0.0;
  for (int skip = 0; skip < 4; ++skip) {
    Vec3 p[3];
    for (int i = 0, k = 0; i < 4; ++i)
      if (i != skip) p[k++] = vec3_at(x, n[i]);
    largest_area = std::max(largest_area, 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm());
  }
  const double height = largest_area > 0 ? 3.0 * volume / largest_area : 0.0;
  const std::int32_t body = model.pieces.body_of(model.tets.piece[tet]);
  std::ostringstream out;
  out.precision(3);
  out << "tetrahedron " << model.tets.gid[tet] << " of body '" << model.body_names[body]
      << "' (smallest height " << height << " m)";
  return out.str();
}

}  // namespace fdem
