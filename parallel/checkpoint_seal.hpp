// The seal of a checkpoint file: a checksum of its HDF5 metadata (every byte outside the
// datasets' raw data), kept in the HDF5 userblock at the start of the file and checked before
// HDF5 parses the file.  HDF5 reading damaged metadata can fail in ways that leak (HDF5 1.10
// then prints "infinite loop closing library" at exit) or, worse, succeed with other values;
// the datasets' own checksums (checkpoint_checksum.hpp) cover the raw data and name the dataset.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fdem {

// Size of the HDF5 userblock that holds the seal (bytes; HDF5 wants a power of two >= 512).
constexpr std::uint64_t checkpoint_seal_bytes = 4096;

// A dataset's raw data in the file: byte offset from the start of the file, length.
struct FileRegion {
  std::uint64_t offset = 0, size = 0;
};

// Writes the seal of the closed HDF5 file `path` into its userblock.  Throws IoError naming the
// file as a `kind` ("checkpoint", "model file").
void write_checkpoint_seal(const std::string& path, std::vector<FileRegion> data,
                           const std::string& kind = "checkpoint");

enum class SealState { intact, absent, damaged };

// Checks the seal of `path`; on `damaged`, `problem` says what does not match.
SealState check_checkpoint_seal(const std::string& path, std::string& problem);

}  // namespace fdem
