#include "parallel/exact_sum_reduction.hpp"

#include <mpi.h>

#include <cstdint>

namespace fdem {

void reduce_exact_sums_to_root(std::vector<ExactSum>& sums, const Communicator& comm) {
  constexpr int tag = 13;  // apart from the halo exchange's (8), which may be in flight
  const int rank = comm.rank(), size = comm.size();
  // Round k: ranks with bit k set send to rank − 2^k, which adds them; exact sums merge in any
  // order, so the tree's shape does not show in the result.
  for (int mask = 1; mask < size; mask <<= 1) {
    if (rank & mask) {
      std::vector<std::int64_t> words;
      for (const ExactSum& s : sums) s.append_words(words);
      MPI_Send(words.data(), detail::checked_count(words.size(), 1), MPI_INT64_T, rank - mask, tag,
               comm.handle());
      return;
    }
    if (rank + mask >= size) continue;
    MPI_Status status;
    MPI_Probe(rank + mask, tag, comm.handle(), &status);
    int count = 0;
    MPI_Get_count(&status, MPI_INT64_T, &count);
    std::vector<std::int64_t> words(static_cast<std::size_t>(count));
    MPI_Recv(words.data(), count, MPI_INT64_T, rank + mask, tag, comm.handle(), MPI_STATUS_IGNORE);
    const std::int64_t* at = words.data();
    for (ExactSum& s : sums) s.add(ExactSum::from_words(at));
    FDEM_VERIFY(at == words.data() + words.size(), "the words of every sum were read");
  }
}

}  // namespace fdem
