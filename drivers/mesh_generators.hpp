// Scene mesh generators (the `mesh:` kinds besides `file`).
#pragma once

#include <functional>

#include "core/model_builder.hpp"
#include "core/scene.hpp"

namespace fdem {

// A box split into nx·ny·nz cubes of 6 tetrahedra each (Kuhn subdivision along the main diagonal:
// conforming, every tet of the same shape).
BodyMesh box_mesh(const BoxMeshSpec& box);

// A generated mesh of several separate pieces (units): each piece has its own nodes, and pieces
// that touch share identical boundary triangles (conforming), so `joints: interfaces` can bond
// them.  Tets are positively oriented.

// A hexahedron meshed like box_mesh over the parameter cube [0,1]³, every node mapped through
// `map(u, v, w)` (u, v, w exactly 0 and 1 on the faces).  Orientation is fixed after mapping.
BodyMesh mapped_box_mesh(const int cells[3],
                         const std::function<Vec3(double, double, double)>& map);

// Wall (stack or running bond), arch (curved-wedge voussoirs with radial joints, optional
// abutments) and tower (stacked blocks).  Throws InputError on impossible dimensions.
BodyMesh wall_mesh(const WallMeshSpec& wall);
BodyMesh arch_mesh(const ArchMeshSpec& arch);
BodyMesh tower_mesh(const TowerMeshSpec& tower);

// Appends `piece`'s nodes and tets to `mesh` (its nodes stay separate from the others').
void append_piece(BodyMesh& mesh, const BodyMesh& piece);

// Chunked generation (distributed start-up): a box body splits into rows of cells (fixed j, k), a
// wall, tower or arch into its units (one piece each).  Chunk by chunk the same nodes, tets and
// corner order as box_mesh / wall_mesh / tower_mesh / arch_mesh.  Throws InputError for a mesh
// read from a file (it has no chunked form).
// `ranks`: the rank count the chunks are dealt to; box bodies are cut into blocks of 2–8 cells a
// side, small enough that each rank gets dozens of them (a finer deal follows the ranks' blocks of
// the space-filling curve more closely), large enough that the plan stays small.
BodyChunks body_chunks(const MeshSpec& mesh, int ranks = 1);

// How messages name a file mesh: "part.msh [group]".
std::string mesh_source(const MeshSpec& mesh);

// Loads or generates the mesh of every body of the scene, in scene order.  A file mesh is a Gmsh
// file or a model file prepared from one (`fdem prepare`; the same mesh).
std::vector<BodyMesh> load_body_meshes(const Scene& scene);

}  // namespace fdem
