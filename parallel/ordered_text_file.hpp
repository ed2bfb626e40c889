// Appends text to one file from every rank with MPI-IO: each call writes the ranks' texts one
// after the other in rank order at the file's end (offsets from an exclusive scan of the byte
// counts), so rows formatted where their data lives (bodies.csv at the pieces' directory ranks)
// reach the file without passing through one rank.
#pragma once

#include <cstdint>
#include <string>

#include "parallel/communicator.hpp"

namespace fdem {

class OrderedTextFile {
 public:
  // `path` exists already (rank 0 wrote its header); appends start at byte `end`.
  OrderedTextFile(std::string path, std::int64_t end, const Communicator& comm);

  // Collective.  Rank 0 first claims the bytes (fallocate), so a full disk stops every rank
  // together with an IoError before anything is written; so does a failed open or write.  Ends
  // every rank (MPI_Abort, exit code 4) when the file opened on some ranks only.
  void append(const std::string& text);

 private:
  std::string path_;
  std::int64_t end_ = 0;
  Communicator comm_;
};

}  // namespace fdem
