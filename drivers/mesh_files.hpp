// File meshes on N ranks: the model file a distributed start reads for a body with
// `mesh: {file: ...}` — the file itself when it is a model file (`fdem prepare`), else the Gmsh
// file prepared once into the run's output directory (docs/scene-format.md, "Body").
#pragma once

#include <string>

#include "core/scene.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Where a distributed start of a run writing to `output_dir` keeps the model file prepared from
// the Gmsh file `msh`: output_dir/prepared/<stem>-<hash of msh's absolute path>.h5.
std::string prepared_model_path(const std::string& msh, const std::string& output_dir);

// Collective.  The model file to read for `mesh` (a file mesh): `mesh.file` when it is an HDF5
// file; else the prepared model file, which rank 0 (re)writes unless it is there already and was
// prepared from this very file (same path, size and modification time).  A bad mesh or an
// unwritable directory is a collective error on every rank (InputError, IoError).
std::string model_file_for(const MeshSpec& mesh, const std::string& output_dir,
                           const Communicator& comm);

}  // namespace fdem
