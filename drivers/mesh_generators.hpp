// Scene mesh generators (the `mesh:` kinds besides `file`).
#pragma once

#include "core/model_builder.hpp"
#include "core/scene.hpp"

namespace fdem {

// A box split into nx·ny·nz cubes of 6 tetrahedra each (Kuhn subdivision along the main diagonal:
// conforming, every tet of the same shape).
BodyMesh box_mesh(const BoxMeshSpec& box);

// Loads or generates the mesh of every body of the scene, in scene order.
std::vector<BodyMesh> load_body_meshes(const Scene& scene);

}  // namespace fdem
