// libFuzzer harness of the YAML scene reader: any input must give a Scene or an InputError (a
// located message); anything else — another exception, a crash, a sanitizer report, a hang — is
// a finding.  Each input is also read with one --set override (the override path is its own
// parser).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scene_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    fdem::parse_scene(text, "fuzz.yaml", {});
  } catch (const fdem::InputError&) {
  }
  // The first line, when short, as an override: "key.path=value".
  const std::string first = text.substr(0, text.find('\n'));
  if (first.size() < 200 && first.find('=') != std::string::npos) {
    try {
      fdem::parse_scene(
          "time: {end: 1}\nmaterials: {m: {density: 1, elastic: {young: 1, "
          "poisson: 0}}}\nbodies: [{mesh: {box: {min: [0,0,0], max: [1,1,1]}}, "
          "material: m}]\n",
          "fuzz.yaml", {first});
    } catch (const fdem::InputError&) {
    }
  }
  return 0;
}
