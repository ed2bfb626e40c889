// libFuzzer harness of the Gmsh 4.1 reader (ASCII and binary): any input must give a mesh or an
// InputError; anything else is a finding.  The mesh is read whole and, when it has a 3D
// physical group, also filtered by the first one.  The same bytes are also streamed from a file
// through a 64-byte window, as `fdem prepare` reads (io/gmsh_cursor): the parse must hand over the
// same nodes and tets, or fail with the same message — else abort (a finding).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "io/gmsh_cursor.hpp"
#include "io/gmsh_parser.hpp"
#include "io/gmsh_reader.hpp"

namespace {

// A hash of everything the parser hands over.
struct Digest : fdem::GmshSink {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i)
      h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  }
  void node_tag(std::int64_t index, std::int64_t tag) override {
    add(&index, 8);
    add(&tag, 8);
  }
  void node_coords(std::int64_t index, const double (&x)[3]) override {
    add(&index, 8);
    add(x, 24);
  }
  void tet(std::int64_t tag, int entity, const std::int64_t (&nodes)[4]) override {
    add(&tag, 8);
    add(&entity, 4);
    add(nodes, 32);
  }
};

// The digest and table sizes, or the error message.
std::string parse(fdem::gmsh::Cursor& cur, const std::string& path,
                  std::unique_ptr<fdem::NodeTagIndex> index) {
  Digest digest;
  try {
    const fdem::GmshTables t = fdem::parse_gmsh_sections(cur, path, *index, digest);
    return std::to_string(digest.h) + " " + std::to_string(t.n_nodes) + " " +
           std::to_string(t.n_tets) + " " + std::to_string(t.names_3d.size()) + " " +
           std::to_string(t.volume_physicals.size()) + " " + std::to_string(t.unsupported.size());
  } catch (const fdem::InputError& e) {
    return e.what();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const fdem::GmshMesh mesh = fdem::parse_gmsh(bytes, "fuzz.msh");
    if (!mesh.physical_names.empty())
      fdem::parse_gmsh(bytes, "fuzz.msh", mesh.physical_names.begin()->first);
  } catch (const fdem::InputError&) {
  }
  static const std::string path = "/tmp/fuzz_gmsh_stream_" + std::to_string(getpid()) + ".msh";
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(size));
  fdem::gmsh::Cursor whole(path, bytes);
  const std::string expected = parse(whole, path, fdem::make_table_index());
  std::string streamed;
  try {
    fdem::gmsh::Cursor window(path, 64);
    streamed = parse(window, path, fdem::make_run_index());
  } catch (const fdem::InputError& e) {
    streamed = e.what();
  }
  if (streamed != expected) {
    std::fprintf(stderr, "streamed parse differs:\n  whole:    %s\n  streamed: %s\n",
                 expected.c_str(), streamed.c_str());
    std::abort();
  }
  return 0;
}
