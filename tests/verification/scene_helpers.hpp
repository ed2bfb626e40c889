// Small builders for verification scenes made in code (no YAML needed).
#pragma once

#include <memory>

#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/simulation.hpp"

namespace fdem::testing {

inline MaterialSpec elastic_material(double density, double young, double poisson,
                                     ElasticModel model = ElasticModel::neo_hookean) {
  MaterialSpec m;
  m.name = "material";
  m.density = density;
  m.elastic.model = model;
  m.elastic.young = young;
  m.elastic.poisson = poisson;
  return m;
}

inline BodySpec box_body(const std::string& name, const Vec3& lo, const Vec3& hi, int nx, int ny,
                         int nz, int material = 0) {
  BodySpec b;
  b.name = name;
  b.material = material;
  b.mesh.kind = MeshSpec::Kind::box;
  b.mesh.box.min = lo;
  b.mesh.box.max = hi;
  b.mesh.box.cells[0] = nx;
  b.mesh.box.cells[1] = ny;
  b.mesh.box.cells[2] = nz;
  return b;
}

inline Scene basic_scene(double end_time) {
  Scene s;
  s.name = "verification";
  s.source_path = "verification";
  s.time.end = end_time;
  return s;
}

// A simulation without output files.
inline std::unique_ptr<Simulation> quiet_simulation(const Scene& scene) {
  RunOptions options;
  options.quiet = true;
  options.write_output = false;
  return make_simulation(scene, options);
}

}  // namespace fdem::testing
