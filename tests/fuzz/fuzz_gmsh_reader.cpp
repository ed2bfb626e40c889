// libFuzzer harness of the Gmsh 4.1 reader (ASCII and binary): any input must give a mesh or an
// InputError; anything else is a finding.  The mesh is read whole and, when it has a 3D
// physical group, also filtered by the first one.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "io/gmsh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const fdem::GmshMesh mesh = fdem::parse_gmsh(bytes, "fuzz.msh");
    if (!mesh.physical_names.empty())
      fdem::parse_gmsh(bytes, "fuzz.msh", mesh.physical_names.begin()->first);
  } catch (const fdem::InputError&) {
  }
  return 0;
}
