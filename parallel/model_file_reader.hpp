// Reading a model file (parallel/model_file.hpp): by one process (serial HDF5), or by every rank
// of a communicator (MPI-IO, collective metadata reads) where each rank then reads its own rows
// independently.  Internal to parallel/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/gmsh_parser.hpp"
#include "parallel/communicator.hpp"
#include "parallel/hdf5_support.hpp"
#include "parallel/model_file.hpp"
#include "parallel/model_file_layout.hpp"

namespace fdem::model_file {

class Reader {
 public:
  // Opens `path` and checks it: the seal of its metadata (before HDF5 parses it), format,
  // version, the header's checksum, every dataset's type and shape; reads and checks the tables.
  // With `comm`, collective: a problem is a CollectiveInputError on every rank.
  Reader(const std::string& path, const Communicator* comm);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const ModelFileHeader& header() const { return header_; }
  const GmshTables& tables() const { return tables_; }
  const hdf5::Context& context() const { return ctx_; }
  // "model file 'x.h5' (prepared from 'x.msh')": the start of messages about the mesh.
  std::string label() const;

  // Rows [first, first + count) of a dataset (`width` values each), read by this process alone.
  // Throws InputError.
  template <class T>
  std::vector<T> rows(DatasetInfo info, std::int64_t first, std::int64_t count) const;
  // The checksum the file stores for a dataset.
  std::uint64_t stored_checksum(DatasetInfo info) const;
  // Throws the "does not match its checksum" InputError for `info`.
  [[noreturn]] void corrupt(DatasetInfo info) const;

 private:
  template <class F>
  void step(F&& f) const {
    if (comm_)
      comm_->run_collectively(f);
    else
      f();
  }
  hid_t dataset(DatasetInfo info) const;

  hdf5::Context ctx_;
  const Communicator* comm_;
  hdf5::SilenceHdf5Errors silence_;
  hdf5::Handle file_;
  std::vector<std::pair<std::string, hdf5::Handle>> datasets_;
  std::vector<std::pair<std::string, std::uint64_t>> checksums_;
  ModelFileHeader header_;
  GmshTables tables_;
};

}  // namespace fdem::model_file
