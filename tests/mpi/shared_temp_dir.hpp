// A directory under /tmp that rank 0 creates and removes; every rank gets its name.  For MPI
// tests that write files (checkpoints, XDMF frames).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include "parallel/communicator.hpp"

namespace fdem {

class SharedTempDir {
 public:
  // `kind` goes into the name: /tmp/fdem-<kind>-test-<pid>-<counter>.
  SharedTempDir(const Communicator& comm, const std::string& kind) : comm_(comm) {
    namespace fs = std::filesystem;
    std::string name;
    if (comm.is_root()) {
      static int counter = 0;
      name = (fs::temp_directory_path() / ("fdem-" + kind + "-test-" + std::to_string(::getpid()) +
                                           "-" + std::to_string(counter++)))
                 .string();
      fs::remove_all(name);
      fs::create_directories(name);
    }
    path_ = comm.broadcast(name, 0);
  }
  ~SharedTempDir() {
    comm_.barrier();
    if (comm_.is_root()) {
      std::error_code ignored;
      std::filesystem::remove_all(path_, ignored);
    }
  }
  SharedTempDir(const SharedTempDir&) = delete;
  SharedTempDir& operator=(const SharedTempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  Communicator comm_;
  std::string path_;
};

}  // namespace fdem
