// core/surface_loads: the corner forces of a triangle, which faces are boundary faces (shared
// faces and joint faces are not), their outward order, and a closed surface's zero resultant.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/model_builder.hpp"
#include "core/surface_loads.hpp"

using namespace fdem;

namespace {

// A unit tet alone, and a piece of two tets sharing the face 5-6-7.
BodyMesh two_pieces() {
  BodyMesh m;
  m.source = "test";
  m.coords = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1, 6, 1, 1};
  m.tets = {0, 1, 2, 3, 4, 5, 6, 7, 5, 8, 6, 7};
  return m;
}

Scene one_body(bool jointed) {
  Scene s;
  s.source_path = "test.yaml";
  MaterialSpec m;
  m.name = "rock";
  m.density = 2000;
  m.elastic.young = 1e9;
  m.elastic.poisson = 0.2;
  if (jointed) {
    FractureSpec f;
    f.tensile_strength = 1e6;
    f.cohesion = 2e6;
    f.friction_angle_deg = 30.0;
    f.energy_I = 10.0;
    f.energy_II = 50.0;
    m.fracture = f;
  }
  s.materials.push_back(m);
  BodySpec body;
  body.name = "b";
  body.material = 0;
  if (jointed) body.joints = JointPlacement::all;
  s.bodies.push_back(body);
  return s;
}

LoadSpec pressure_on(const std::vector<int>& bodies, double p) {
  LoadSpec load;
  load.kind = LoadSpec::Kind::surface;
  load.bodies = bodies;
  load.surface.pressure = p;
  return load;
}

}  // namespace

TEST_CASE("surface loads: a triangle's corner forces are a third of p·a and of t·|a|",
          "[core][surface_loads]") {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 3, 0);  // area 3 m², normal +z
  CHECK((pressure_corner_force(a, b, c, 6.0) - Vec3(0, 0, -6.0)).norm() < 1e-14);  // −6·3/3
  CHECK((traction_corner_force(a, b, c, Vec3(1, 2, 0)) - Vec3(1, 2, 0)).norm() < 1e-14);
}

TEST_CASE("surface loads: boundary faces, outward, without shared or joint faces",
          "[core][surface_loads]") {
  for (bool jointed : {false, true}) {
    INFO((jointed ? "joints: all" : "no joints"));
    Model model = build_model(one_body(jointed), {two_pieces()});
    CHECK(model.joints.size() == (jointed ? 1 : 0));
    const double p = 1.0e3;  // Pa
    LoadSpec load = pressure_on({0}, p);
    SurfaceFaces faces = select_surface_faces(model, load);
    REQUIRE(faces.size() == 4 + 6);  // the lone tet's 4, the pair's 6 (their shared face is not)
    for (std::size_t i = 1; i < faces.tet.size(); ++i) CHECK(faces.tet[i - 1] <= faces.tet[i]);
    std::fill(model.nodes.f.begin(), model.nodes.f.end(), 0.0);
    add_surface_forces(load.surface, 1.0, faces, model.nodes);
    // Closed surfaces: no resultant; every face pushed inwards (towards its piece's centroid).
    CHECK(surface_resultant(faces).norm() < 1e-9 * p);
    double area = 0;
    for (LocalIndex i = 0; i < faces.size(); ++i) {
      const Vec3 force = vec3_at(faces.corner_force.data(), i);
      const LocalIndex* n = faces.nodes.data() + 3 * i;
      const Vec3 centre =
          (model.nodes.x0(n[0]) + model.nodes.x0(n[1]) + model.nodes.x0(n[2])) / 3.0;
      const Vec3 piece_centre = centre.x() < 3 ? Vec3(0.25, 0.25, 0.25) : Vec3(5.5, 0.5, 0.5);
      CHECK(force.dot(piece_centre - centre) > 0.0);
      area += 3.0 * force.norm() / p;
    }
    // The unit tet: 3 × ½ + √3/2; the pair's six faces: their areas from the mesh.
    double pair_area = 0;
    for (LocalIndex i = 0; i < faces.size(); ++i) {
      const LocalIndex* n = faces.nodes.data() + 3 * i;
      const Vec3 x0 = model.nodes.x0(n[0]);
      if (x0.x() < 3) continue;
      pair_area += 0.5 * (model.nodes.x0(n[1]) - x0).cross(model.nodes.x0(n[2]) - x0).norm();
    }
    CHECK(area == Approx(1.5 + std::sqrt(3.0) / 2 + pair_area).epsilon(1e-12));
    // Every node's force is the sum of its faces' corner forces: Σ f = 0 as well.
    Vec3 total = Vec3::Zero();
    for (LocalIndex n = 0; n < model.nodes.size(); ++n) total += vec3_at(model.nodes.f.data(), n);
    CHECK(total.norm() < 1e-9 * p);
  }
}

TEST_CASE("surface loads: a region keeps faces with three corners inside, power is F·v",
          "[core][surface_loads]") {
  Model model = build_model(one_body(false), {two_pieces()});
  LoadSpec load = pressure_on({}, 2.0);
  load.region = RegionSpec{Vec3(-1, -1, -1e-9), Vec3(2, 2, 1e-9)};  // the lone tet's z = 0 face
  SurfaceFaces faces = select_surface_faces(model, load);
  REQUIRE(faces.size() == 1);
  std::fill(model.nodes.f.begin(), model.nodes.f.end(), 0.0);
  add_surface_forces(load.surface, 0.5, faces, model.nodes);  // history factor 0.5: 1 Pa
  // Area ½ on z = 0, outward −z: the pressure pushes +z with ½ N in all.
  CHECK((surface_resultant(faces) - Vec3(0, 0, 0.5)).norm() < 1e-15);
  for (double& v : model.nodes.v) v = 0.0;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n) model.nodes.v[3 * n + 2] = 2.0;  // m/s
  CHECK(surface_power(faces, model.nodes) == Approx(1.0).epsilon(1e-14));  // ½ N × 2 m/s
  // A fixed-direction pressure and a traction act on the reference shape: moving x changes
  // neither; a follower pressure turns with the face.
  for (LocalIndex n = 0; n < model.nodes.size(); ++n) {  // turn everything 90° about x
    const Vec3 X = model.nodes.x0(n);
    vec3_at(model.nodes.x.data(), n) = Vec3(X.x(), -X.z(), X.y());
  }
  add_surface_forces(load.surface, 0.5, faces, model.nodes);
  CHECK((surface_resultant(faces) - Vec3(0, -0.5, 0)).norm() < 1e-15);
  load.surface.follower = false;
  add_surface_forces(load.surface, 0.5, faces, model.nodes);
  CHECK((surface_resultant(faces) - Vec3(0, 0, 0.5)).norm() < 1e-15);
  load.surface.kind = SurfaceLoadSpec::Kind::traction;
  load.surface.traction = Vec3(4, 0, 0);
  add_surface_forces(load.surface, 1.0, faces, model.nodes);
  CHECK((surface_resultant(faces) - Vec3(2, 0, 0)).norm() < 1e-15);
}
