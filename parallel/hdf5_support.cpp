#include "parallel/hdf5_support.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace fdem::hdf5 {

namespace {

herr_t collect_error(unsigned, const H5E_error2_t* error, void* out) {
  auto& lines = *static_cast<std::vector<std::string>*>(out);
  std::string line = error->desc ? error->desc : "";
  char minor[256] = {0};
  if (H5Eget_msg(error->min_num, nullptr, minor, sizeof minor) > 0) {
    if (!line.empty()) line += ": ";
    line += minor;
  }
  std::replace(line.begin(), line.end(), '\n', ' ');
  if (!line.empty() && std::find(lines.begin(), lines.end(), line) == lines.end())
    lines.push_back(line);
  return 0;
}

}  // namespace

std::string hdf5_error_text() {
  std::vector<std::string> lines;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &lines);
  H5Eclear2(H5E_DEFAULT);
  std::string text;
  for (std::size_t i = 0; i < lines.size() && i < 2; ++i) text += (i ? "; " : "") + lines[i];
  return text.empty() ? "no HDF5 error detail" : text;
}

Handle make_mpio_access(const Context& ctx, const Communicator& comm, MPI_Info hints) {
  Handle fapl = make_plist(ctx, H5P_FILE_ACCESS);
  ctx.check_status(H5Pset_fapl_mpio(fapl.get(), comm.handle(), hints),
                   "cannot set up MPI-IO file access");
  ctx.check_status(H5Pset_all_coll_metadata_ops(fapl.get(), 1), "cannot set collective metadata");
  ctx.check_status(H5Pset_coll_metadata_write(fapl.get(), 1), "cannot set collective metadata");
  // Closing the file closes whatever is still open in it, so that a damaged file left on an error
  // path cannot keep the library from shutting down ("infinite loop closing library").
  ctx.check_status(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG), "cannot set close degree");
  // The 1.8 object format allows any number of /run attributes (dense attribute storage).
  ctx.check_status(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST),
                   "cannot set the file format bounds");
  return fapl;
}

void reserve_space(const Context& ctx, const std::string& path, double bytes) {
  const int fd = ::open(path.c_str(), O_CREAT | O_WRONLY | O_TRUNC, 0644);
  if (fd < 0) ctx.fail("cannot create '" + path + "': " + std::strerror(errno));
  const int error = ::fallocate(fd, 0, 0, static_cast<off_t>(bytes)) == 0 ? 0 : errno;
  ::close(fd);
  std::remove(path.c_str());
  if (error != 0 && error != EOPNOTSUPP && error != ENOSYS)
    ctx.fail("no room for the " + ctx.kind() + " (about " +
             std::to_string(std::llround(bytes / 1e6)) + " MB): " + std::strerror(error));
}

void sync_directory_of(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace fdem::hdf5
