#include "parallel/ordered_text_file.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "core/error.hpp"

namespace fdem {

namespace {
// Bytes per MPI write call (counts are ints).
constexpr std::int64_t write_chunk = std::int64_t{1} << 30;

// Allocates bytes [begin, begin + count) of the file (file systems without fallocate: no check).
LocalError claim_space(const std::string& path, std::int64_t begin, std::int64_t count) {
  LocalError error;
  const int fd = ::open(path.c_str(), O_WRONLY);
  if (fd < 0) return {ErrorKind::io, "cannot open " + path + ": " + std::strerror(errno)};
  const int failure =
      ::fallocate(fd, 0, static_cast<off_t>(begin), static_cast<off_t>(count)) == 0 ? 0 : errno;
  ::close(fd);
  if (failure != 0 && failure != EOPNOTSUPP && failure != ENOSYS)
    error = {ErrorKind::io, "cannot write " + path + " (disk full?): " + std::strerror(failure)};
  return error;
}
}  // namespace

OrderedTextFile::OrderedTextFile(std::string path, std::int64_t end, const Communicator& comm)
    : path_(std::move(path)), end_(end), comm_(comm) {}

void OrderedTextFile::append(const std::string& text) {
  const std::int64_t bytes = static_cast<std::int64_t>(text.size());
  const std::int64_t offset = end_ + comm_.sum_over_lower_ranks(bytes);
  const std::int64_t total = comm_.sum(bytes);
  if (total == 0) return;
  // Every rank writes as many chunks as the rank with the longest text (collective calls).
  const std::int64_t rounds = comm_.max((bytes + write_chunk - 1) / write_chunk);
  // Rank 0 claims the bytes first: a full disk (or file size limit) is then reported by every
  // rank together; MPI-IO may lose a failed write of an aggregating rank.
  LocalError claim;
  if (comm_.rank() == 0) claim = claim_space(path_, end_, total);
  comm_.check_errors(claim);
  MPI_File file;
  const bool opened = MPI_File_open(comm_.handle(), path_.c_str(), MPI_MODE_WRONLY, MPI_INFO_NULL,
                                    &file) == MPI_SUCCESS;
  const int opened_ranks = comm_.sum(opened ? 1 : 0);
  if (opened_ranks == 0) throw IoError("cannot open " + path_ + " for writing");
  if (opened_ranks != comm_.size())  // the handle exists on some ranks: no collective close
    comm_.abort_all("cannot open " + path_ + " for writing on every rank", 4);
  bool written = true;
  for (std::int64_t r = 0; r < rounds; ++r) {
    const std::int64_t begin = std::min(bytes, r * write_chunk);
    const std::int64_t count = std::min(bytes - begin, write_chunk);
    MPI_Status status;
    const bool call_ok =
        MPI_File_write_at_all(file, static_cast<MPI_Offset>(offset + begin), text.data() + begin,
                              static_cast<int>(count), MPI_CHAR, &status) == MPI_SUCCESS;
    // A full disk (or a file size limit) may end a write early without an error code.
    int done = 0;
    written = written && call_ok && MPI_Get_count(&status, MPI_CHAR, &done) == MPI_SUCCESS &&
              done == count;
  }
  written = MPI_File_close(&file) == MPI_SUCCESS && written;
  LocalError error;
  if (!written) error = {ErrorKind::io, "cannot write " + path_ + " (disk full?)"};
  comm_.check_errors(error);
  end_ += total;
}

}  // namespace fdem
