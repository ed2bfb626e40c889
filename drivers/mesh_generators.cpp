#include "drivers/mesh_generators.hpp"

#include <algorithm>
#include <sstream>

#include "core/error.hpp"
#include "core/tet_kernels.hpp"
#include "io/gmsh_reader.hpp"

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

std::vector<BodyMesh> load_body_meshes(const Scene& scene) {
  std::vector<BodyMesh> meshes;
  for (const BodySpec& body : scene.bodies) {
    if (body.mesh.kind == MeshSpec::Kind::box) {
      meshes.push_back(box_mesh(body.mesh.box));
    } else {
      const GmshMesh g = read_gmsh(body.mesh.file, body.mesh.physical);
      BodyMesh mesh;
      mesh.source =
          body.mesh.file + (body.mesh.physical.empty() ? "" : " [" + body.mesh.physical + "]");
      mesh.coords = g.coords;
      mesh.tets.assign(g.tets.begin(), g.tets.end());
      mesh.source_tags.assign(g.tet_tags.begin(), g.tet_tags.end());
      meshes.push_back(std::move(mesh));
    }
  }
  return meshes;
}

}  // namespace fdem
