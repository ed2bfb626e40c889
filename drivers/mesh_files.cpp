#include "drivers/mesh_files.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/model_file.hpp"

namespace fdem {

namespace {

// The model file at `h5` was prepared from `msh` as it is now.
bool prepared_from(const std::string& h5, const std::string& msh) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(h5, error)) return false;
  struct stat status {};
  if (::stat(msh.c_str(), &status) != 0) return false;
  try {
    const ModelFileHeader header = read_model_file_header(h5);
    return header.source == msh && header.source_bytes == status.st_size &&
           header.source_mtime_ns == static_cast<std::int64_t>(status.st_mtim.tv_sec) * 1000000000 +
                                         status.st_mtim.tv_nsec;
  } catch (const InputError&) {
    return false;  // damaged or foreign: prepared again
  }
}

}  // namespace

std::string prepared_model_path(const std::string& msh, const std::string& output_dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path absolute = fs::absolute(msh, error);
  char hash[17];
  std::snprintf(hash, sizeof hash, "%08llx",
                static_cast<unsigned long long>(text_checksum(absolute.string()) & 0xffffffffu));
  return (fs::path(output_dir) / "prepared" / (fs::path(msh).stem().string() + "-" + hash + ".h5"))
      .string();
}

std::string model_file_for(const MeshSpec& mesh, const std::string& output_dir,
                           const Communicator& comm) {
  if (is_hdf5_file(mesh.file)) return mesh.file;
  const std::string h5 = prepared_model_path(mesh.file, output_dir);
  comm.run_collectively([&] {
    if (!comm.is_root() || prepared_from(h5, mesh.file)) return;
    std::error_code error;
    std::filesystem::create_directories(std::filesystem::path(h5).parent_path(), error);
    if (error)
      throw InputError("cannot create the output directory '" + output_dir +
                       "' (-o) for the prepared mesh: " + error.message());
    prepare_model_file(mesh.file, h5);
  });
  return h5;
}

}  // namespace fdem
