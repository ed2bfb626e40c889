// The MPI layer: environment (init/finalize), a communicator value with the reductions and
// gathers the engine needs, and the two failure paths of a parallel run.  Every MPI call of fdem
// lives in parallel/; physics sees plain arrays.
//
// Failure paths (LAMMPS error->all / error->one):
// - Collective: at a synchronisation point every rank calls `Communicator::check_errors` with
//   its local error (or none).  If any rank failed, every rank throws the same exception type
//   (InputError / NumericalFailure / std::logic_error for internal errors) carrying the message
//   of the lowest failing rank, so all ranks leave the run together, print once, and finalize.
//   Use it for everything that can be detected at a point all ranks reach: reading and checking
//   the scene, building and partitioning the model, the per-step health check (NaN, inverted
//   tets, energy balance), writing output and checkpoints.
// - Abort now: `abort_all` prints the message with the rank and calls MPI_Abort with a non-zero
//   code.  Use it where one rank alone finds an error that the others cannot learn about without
//   a synchronisation point they may never reach (an exception inside a halo exchange, an
//   internal invariant broken between two collectives, an exception that escapes to main on one
//   rank only).  `MpiEnvironment` also installs a terminate handler that aborts all ranks.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"

namespace fdem {

// Initialises MPI (thread level funneled: only the main thread calls MPI) and finalises it at
// scope exit.  If MPI is already initialised (a test harness, a host program) it does neither.
// If the scope is left by an exception that not every rank shares (see CollectiveFailure), the
// destructor aborts all ranks instead of finalising, because MPI_Finalize would wait for ranks
// that are blocked in a collective.
class MpiEnvironment {
 public:
  MpiEnvironment(int* argc, char*** argv);
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  bool owns_mpi() const { return owns_; }
  int thread_level() const { return provided_; }

 private:
  bool owns_ = false;
  int provided_ = MPI_THREAD_SINGLE;
};

// What one rank found before a synchronisation point.
enum class ErrorKind : std::int32_t { none = 0, input = 1, numerical = 2, internal = 3, io = 4 };

struct LocalError {
  ErrorKind kind = ErrorKind::none;
  std::string message;

  bool failed() const { return kind != ErrorKind::none; }
  // Classifies a caught exception: InputError → input, NumericalFailure → numerical, IoError →
  // io, anything else → internal (its what(), or "unknown exception").
  static LocalError from(std::exception_ptr error);
};

// Tag carried by the exceptions check_errors throws: every rank throws one at the same point.
class CollectiveFailure {
 public:
  CollectiveFailure(int first_rank, int failed_ranks);
  CollectiveFailure(const CollectiveFailure& other);
  virtual ~CollectiveFailure();
  int first_rank() const { return first_rank_; }      // lowest rank that failed
  int failed_ranks() const { return failed_ranks_; }  // how many ranks failed at this point
  static int live_count();  // collective exceptions alive in this process (for MpiEnvironment)

 private:
  int first_rank_;
  int failed_ranks_;
};

class CollectiveInputError : public InputError, public CollectiveFailure {
 public:
  CollectiveInputError(const std::string& what, int first_rank, int failed_ranks)
      : InputError(what), CollectiveFailure(first_rank, failed_ranks) {}
};

class CollectiveNumericalFailure : public NumericalFailure, public CollectiveFailure {
 public:
  CollectiveNumericalFailure(const std::string& what, int first_rank, int failed_ranks)
      : NumericalFailure(what), CollectiveFailure(first_rank, failed_ranks) {}
};

class CollectiveIoError : public IoError, public CollectiveFailure {
 public:
  CollectiveIoError(const std::string& what, int first_rank, int failed_ranks)
      : IoError(what), CollectiveFailure(first_rank, failed_ranks) {}
};

class CollectiveInternalError : public std::logic_error, public CollectiveFailure {
 public:
  CollectiveInternalError(const std::string& what, int first_rank, int failed_ranks)
      : std::logic_error(what), CollectiveFailure(first_rank, failed_ranks) {}
};

namespace detail {
template <class T>
MPI_Datatype mpi_type() {
  static_assert(std::is_trivially_copyable_v<T>, "MPI helpers move plain values only");
  if constexpr (std::is_same_v<T, double>)
    return MPI_DOUBLE;
  else if constexpr (std::is_same_v<T, float>)
    return MPI_FLOAT;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return MPI_INT32_T;
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return MPI_INT64_T;
  else if constexpr (std::is_same_v<T, std::uint64_t>)
    return MPI_UINT64_T;
  else if constexpr (std::is_same_v<T, std::uint8_t>)
    return MPI_UINT8_T;
  else if constexpr (std::is_same_v<T, char>)
    return MPI_CHAR;
  else
    return MPI_BYTE;  // other plain structs travel as bytes (count scaled by sizeof)
}
template <class T>
constexpr bool reducible() {
  return std::is_same_v<T, double> || std::is_same_v<T, float> || std::is_same_v<T, std::int32_t> ||
         std::is_same_v<T, std::int64_t> || std::is_same_v<T, std::uint64_t>;
}
int checked_count(std::size_t n, int scale);  // n·scale as an MPI count, or an internal error
// Most elements one MPI call carries, and the largest displacement it may use: INT_MAX (MPI 3.1
// counts are int).  Larger messages are cut (Communicator::exchange_rows, allgatherv,
// broadcast, element-wise reductions).  Tests lower it to run the chunked paths on small data;
// set_message_limit(0) restores INT_MAX.  Every rank must use the same limit.
std::int64_t message_limit();
void set_message_limit(std::int64_t limit);
}  // namespace detail

// Phases of a run, marked for profiling tools with MPI_Pcontrol(100 + phase) (a no-op without
// one): the communication-budget test's PMPI interposer (tests/mpi/comm_budget) counts the bytes
// each rank receives per phase.
enum class CommPhase : int {
  startup = 1,         // reading the scene, building and distributing the model
  step = 2,            // halo exchange and the per-step reductions
  redistribution = 3,  // re-partition and migration at detection cycles
  output = 4,          // frames, CSV rows
  checkpoint = 5,      // writing a checkpoint
  restart = 6,         // reading a checkpoint
  finish = 7,          // the end-of-run report (counts, state hash, fragments)
};
void mark_phase(CommPhase phase);

// A communicator value (does not own the MPI_Comm).  All members except rank/size are
// collective: every rank of the communicator must call them in the same order.
class Communicator {
 public:
  explicit Communicator(MPI_Comm comm = MPI_COMM_WORLD);
  static Communicator world() { return Communicator(MPI_COMM_WORLD); }

  MPI_Comm handle() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }

  void barrier() const;

  // How many ranks of this communicator share this rank's node (shared-memory domain): they
  // share its memory.
  int ranks_on_this_node() const;

  // Reductions of one value (double, float, int32, int64, uint64).  min/max are order-free, so
  // the same on any rank count; a floating-point sum depends on the rank count (use it for
  // reports, not for anything that steers the run).
  template <class T>
  T min(T value) const {
    return reduce(value, MPI_MIN);
  }
  template <class T>
  T max(T value) const {
    return reduce(value, MPI_MAX);
  }
  template <class T>
  T sum(T value) const {
    return reduce(value, MPI_SUM);
  }
  // Element-wise over a vector of the same length on every rank.
  template <class T>
  void sum_in_place(std::vector<T>& values) const {
    reduce_in_place(values, MPI_SUM);
  }
  template <class T>
  void max_in_place(std::vector<T>& values) const {
    reduce_in_place(values, MPI_MAX);
  }
  template <class T>
  void min_in_place(std::vector<T>& values) const {
    reduce_in_place(values, MPI_MIN);
  }

  // The sum of `value` over the lower ranks (0 on rank 0): where a rank's part of something laid
  // out in rank order begins.
  std::int64_t sum_over_lower_ranks(std::int64_t value) const;

  // One value per rank, in rank order, on every rank.
  template <class T>
  std::vector<T> allgather(const T& value) const;
  // Every rank's array concatenated in rank order, on every rank; `counts` (optional) receives
  // each rank's length.  Counts and offsets are 64-bit (rounds of at most message_limit() rows
  // when the whole does not fit one call).
  template <class T>
  std::vector<T> allgatherv(const std::vector<T>& local,
                            std::vector<std::int64_t>* counts = nullptr) const;

  // Personalised all-to-all: `outbox[r]` goes to rank r (outbox has size() entries); returns
  // what every rank sent here, concatenated in rank order.  `sources` (optional) receives the
  // sending rank of each element.  Elements travel as one MPI type of sizeof(T) bytes; counts
  // and offsets are 64-bit (exchange_rows).
  template <class T>
  std::vector<T> exchange(const std::vector<std::vector<T>>& outbox,
                          std::vector<int>* sources = nullptr) const;
  // The same from one array already grouped by destination: the first counts[0] elements go to
  // rank 0, the next counts[1] to rank 1, ... (no copy of the data is made to send it).
  template <class T>
  std::vector<T> exchange_grouped(const std::vector<T>& grouped,
                                  const std::vector<std::size_t>& counts,
                                  std::vector<int>* sources = nullptr) const;
  // exchange_grouped without a second copy of the data: this rank's own group never leaves
  // `grouped`, only the others travel, and the result (what every rank sent here, in rank order,
  // the own group in its place) is built in grouped's storage when its capacity allows.  For the
  // start-up's sorts, where most rows stay where they are.
  template <class T>
  void exchange_grouped_in_place(std::vector<T>& grouped,
                                 const std::vector<std::size_t>& counts) const;
  // The all-to-all underneath, for rows of a width known at run time: counts first (one
  // MPI_Alltoall of 64-bit counts: what rank r sends here), then the rows.  `send` holds
  // send_rows[r] rows for each rank r in rank order; `receive` gets receive_rows[r] rows from
  // each rank in rank order.  A pair's rows go in the one MPI_Alltoallv when they are at most
  // message_limit() / size() (so no count or displacement of it overflows int), else as
  // point-to-point messages of at most message_limit() rows: any count a 64-bit size allows.
  std::vector<std::int64_t> exchange_counts(const std::vector<std::size_t>& send_rows) const;
  void exchange_rows(const void* send, const std::vector<std::int64_t>& send_rows, void* receive,
                     const std::vector<std::int64_t>& receive_rows, std::size_t row_bytes) const;

  // Neighbour-only exchange (the NBX algorithm of Hoefler, Siebert and Lumsdaine, 2010): the
  // same as exchange(), but only the ranks with something to say send (synchronous sends, then
  // a non-blocking barrier once they are matched), so nothing of length size() travels or is
  // waited on: the messages are what the calls cost.  For exchanges between spatial neighbours
  // (migration, claims, ghost requests).  Returns what arrived, in source rank order.
  template <class T>
  std::vector<T> exchange_sparse(const std::vector<std::vector<T>>& outbox,
                                 std::vector<int>* sources = nullptr) const;
  // The rows underneath: `send` holds send_rows[r] rows of `row_bytes` for each rank r in rank
  // order; returns what arrived in source rank order, with each rank's row count in
  // `receive_rows` (size() entries).
  std::vector<char> exchange_rows_sparse(const void* send,
                                         const std::vector<std::int64_t>& send_rows,
                                         std::size_t row_bytes,
                                         std::vector<std::int64_t>& receive_rows) const;

  // Returns root's string on every rank.
  std::string broadcast(const std::string& text, int root = 0) const;

  // Collective failure check (see top of file).  Returns normally when no rank failed; else every
  // rank throws the kind of the lowest failing rank with the message
  // "rank R: <message>" (+ " (and K more ranks failed)" when several failed).
  void check_errors(const LocalError& local) const;

  // Runs `body` on every rank, catches what it throws, then check_errors.  `body` must not
  // communicate on this communicator (a rank that threw would skip those calls).
  template <class Body>
  void run_collectively(Body&& body) const {
    LocalError local;
    try {
      body();
    } catch (...) {
      local = LocalError::from(std::current_exception());
    }
    check_errors(local);
  }

  // Prints "fdem: rank R of N: <message>" to stderr and ends every rank (MPI_Abort(code)).
  [[noreturn]] void abort_all(const std::string& message, int code = 1) const;

 private:
  template <class T>
  T reduce(T value, MPI_Op op) const {
    static_assert(detail::reducible<T>(), "reductions take double, float, int32, int64 or uint64");
    T result{};
    MPI_Allreduce(&value, &result, 1, detail::mpi_type<T>(), op, comm_);
    return result;
  }
  template <class T>
  void reduce_in_place(std::vector<T>& values, MPI_Op op) const {
    static_assert(detail::reducible<T>(), "reductions take double, float, int32, int64 or uint64");
    const auto limit = static_cast<std::size_t>(detail::message_limit());
    for (std::size_t first = 0; first < values.size(); first += limit)  // same sizes everywhere
      MPI_Allreduce(MPI_IN_PLACE, values.data() + first,
                    static_cast<int>(std::min(limit, values.size() - first)), detail::mpi_type<T>(),
                    op, comm_);
  }
  // Rounds of MPI_Allgatherv of rows of `row_bytes` (counts[r] rows of rank r, known to all).
  void allgather_rows(const void* local, const std::vector<std::int64_t>& counts, void* all,
                      std::size_t row_bytes) const;

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

// abort_all on MPI_COMM_WORLD, usable where no Communicator is at hand (also when MPI is not
// initialised: then it prints and exits with `code`).
[[noreturn]] void abort_all_ranks(const std::string& message, int code = 1);

template <class T>
std::vector<T> Communicator::allgather(const T& value) const {
  static_assert(std::is_trivially_copyable_v<T>, "allgather moves plain values only");
  std::vector<T> all(static_cast<std::size_t>(size_));
  MPI_Allgather(&value, static_cast<int>(sizeof(T)), MPI_BYTE, all.data(),
                static_cast<int>(sizeof(T)), MPI_BYTE, comm_);
  return all;
}

namespace detail {
// The outboxes one after the other (grouped by destination rank), with each one's length.
template <class T>
std::vector<T> grouped(const std::vector<std::vector<T>>& outbox,
                       std::vector<std::size_t>& counts) {
  counts.resize(outbox.size());
  std::size_t total = 0;
  for (std::size_t r = 0; r < outbox.size(); ++r) total += counts[r] = outbox[r].size();
  std::vector<T> send;
  send.reserve(total);
  for (const auto& box : outbox) send.insert(send.end(), box.begin(), box.end());
  return send;
}
// The source rank of each received element: rows[r] elements came from rank r, in rank order.
inline void fill_sources(const std::vector<std::int64_t>& rows, std::vector<int>* sources) {
  if (!sources) return;
  sources->clear();
  for (std::size_t r = 0; r < rows.size(); ++r)
    sources->insert(sources->end(), static_cast<std::size_t>(rows[r]), static_cast<int>(r));
}
}  // namespace detail

template <class T>
std::vector<T> Communicator::exchange(const std::vector<std::vector<T>>& outbox,
                                      std::vector<int>* sources) const {
  FDEM_VERIFY(static_cast<int>(outbox.size()) == size_, "one outbox per rank");
  std::vector<std::size_t> counts;
  const std::vector<T> send = detail::grouped(outbox, counts);
  return exchange_grouped(send, counts, sources);
}

template <class T>
std::vector<T> Communicator::exchange_sparse(const std::vector<std::vector<T>>& outbox,
                                             std::vector<int>* sources) const {
  static_assert(std::is_trivially_copyable_v<T>, "exchange moves plain values only");
  FDEM_VERIFY(static_cast<int>(outbox.size()) == size_, "one outbox per rank");
  std::vector<std::size_t> counts;
  const std::vector<T> send = detail::grouped(outbox, counts);
  std::vector<std::int64_t> receive_rows;
  const std::vector<char> bytes =
      exchange_rows_sparse(send.data(), std::vector<std::int64_t>(counts.begin(), counts.end()),
                           sizeof(T), receive_rows);
  std::vector<T> received(bytes.size() / sizeof(T));
  if (!bytes.empty()) std::memcpy(received.data(), bytes.data(), bytes.size());
  detail::fill_sources(receive_rows, sources);
  return received;
}

template <class T>
std::vector<T> Communicator::exchange_grouped(const std::vector<T>& grouped,
                                              const std::vector<std::size_t>& counts,
                                              std::vector<int>* sources) const {
  static_assert(std::is_trivially_copyable_v<T>, "exchange moves plain values only");
  FDEM_VERIFY(static_cast<int>(counts.size()) == size_, "one count per rank");
  std::size_t total = 0;
  for (std::size_t c : counts) total += c;
  FDEM_VERIFY(total == grouped.size(), "the counts cover the grouped array");
  const std::vector<std::int64_t> send_rows(counts.begin(), counts.end());
  const std::vector<std::int64_t> receive_rows = exchange_counts(counts);
  total = 0;
  for (std::int64_t c : receive_rows) total += static_cast<std::size_t>(c);
  std::vector<T> received(total);
  exchange_rows(grouped.data(), send_rows, received.data(), receive_rows, sizeof(T));
  detail::fill_sources(receive_rows, sources);
  return received;
}

template <class T>
void Communicator::exchange_grouped_in_place(std::vector<T>& grouped,
                                             const std::vector<std::size_t>& counts) const {
  static_assert(std::is_trivially_copyable_v<T>, "exchange moves plain values only");
  FDEM_VERIFY(static_cast<int>(counts.size()) == size_, "one count per rank");
  std::size_t own_begin = 0, total = 0;
  for (int r = 0; r < size_; ++r) {
    if (r < rank_) own_begin += counts[r];
    total += counts[r];
  }
  FDEM_VERIFY(total == grouped.size(), "the counts cover the grouped array");
  const std::size_t own = counts[rank_], own_end = own_begin + own;
  std::vector<std::int64_t> send_rows(counts.begin(), counts.end());
  send_rows[rank_] = 0;
  std::vector<T> moving;
  moving.reserve(grouped.size() - own);
  moving.insert(moving.end(), grouped.begin(), grouped.begin() + own_begin);
  moving.insert(moving.end(), grouped.begin() + own_end, grouped.end());
  std::vector<std::size_t> moving_counts(counts);
  moving_counts[rank_] = 0;
  const std::vector<std::int64_t> receive_rows = exchange_counts(moving_counts);
  std::size_t lower = 0, received_total = 0;
  for (int r = 0; r < size_; ++r) {
    if (r < rank_) lower += static_cast<std::size_t>(receive_rows[r]);
    received_total += static_cast<std::size_t>(receive_rows[r]);
  }
  std::vector<T> received(received_total);
  exchange_rows(moving.data(), send_rows, received.data(), receive_rows, sizeof(T));
  moving = std::vector<T>{};
  const std::size_t size = received_total + own;
  if (size > grouped.capacity()) {  // no room: one new array after all
    std::vector<T> out;
    out.reserve(size);
    out.insert(out.end(), received.begin(), received.begin() + lower);
    out.insert(out.end(), grouped.begin() + own_begin, grouped.begin() + own_end);
    out.insert(out.end(), received.begin() + lower, received.end());
    grouped.swap(out);
    return;
  }
  if (lower > own_begin) {  // the own group moves up
    if (size > grouped.size()) grouped.resize(size);
    std::move_backward(grouped.begin() + own_begin, grouped.begin() + own_end,
                       grouped.begin() + lower + own);
  } else {
    std::move(grouped.begin() + own_begin, grouped.begin() + own_end, grouped.begin() + lower);
  }
  grouped.resize(size);
  std::copy(received.begin(), received.begin() + lower, grouped.begin());
  std::copy(received.begin() + lower, received.end(), grouped.begin() + lower + own);
}

template <class T>
std::vector<T> Communicator::allgatherv(const std::vector<T>& local,
                                        std::vector<std::int64_t>* counts) const {
  static_assert(std::is_trivially_copyable_v<T>, "allgatherv moves plain values only");
  const std::vector<std::int64_t> rows = allgather(static_cast<std::int64_t>(local.size()));
  std::size_t total = 0;
  for (std::int64_t c : rows) total += static_cast<std::size_t>(c);
  std::vector<T> all(total);
  allgather_rows(local.data(), rows, all.data(), sizeof(T));
  if (counts) *counts = rows;
  return all;
}

}  // namespace fdem
