// Running the `fdem` command from a test: a temporary working directory, files in and out, and
// the exit code with stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fdem_test {

namespace fs = std::filesystem;

// A fresh directory under the system temp folder, removed with everything in it at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "fdem_cli_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temp directory");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  REQUIRE(out.good());
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

// Runs `fdem ARGS` inside `dir` (so relative paths and the default output land there), after the
// shell commands `setup` (e.g. a ulimit) if given.
inline Outcome run_fdem(const TempDir& dir, const std::string& args,
                        const std::string& setup = "") {
  INFO("the fdem executable must be built first: " << FDEM_BINARY);
  REQUIRE(fs::exists(FDEM_BINARY));
  const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = "cd '" + dir.path().string() + "' && " + setup + " '" + FDEM_BINARY +
                              "' " + args + " >'" + out + "' 2>'" + err + "'";
  const int status = std::system(command.c_str());
  Outcome o;
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = read_text(out);
  o.err = read_text(err);
  return o;
}

// The critical step (s) that `fdem check` prints ("critical X s"); 0 if it prints none.
inline double critical_step_from_check(const std::string& check_output) {
  std::smatch m;
  const std::regex critical(R"(critical ([0-9.eE+-]+) s)");
  if (!std::regex_search(check_output, m, critical)) return 0.0;
  return std::stod(m[1]);
}

// x as printf's %g writes it: what a --set value on the command line looks like.
inline std::string format_g(double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%g", x);
  return buffer;
}

}  // namespace fdem_test
