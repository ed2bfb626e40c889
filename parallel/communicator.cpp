#include "parallel/communicator.hpp"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <thread>

namespace fdem {

namespace {

std::atomic<int> g_live_collective{0};
std::atomic<std::int64_t> g_message_limit{INT_MAX};
constexpr int chunk_tag = 7001;   // point-to-point chunks of exchange_rows (halo uses 8)
constexpr int sparse_tag = 7010;  // exchange_rows_sparse: 7010 and 7011 in turn

// A contiguous MPI type of `bytes` bytes (freed at scope exit).
class RowType {
 public:
  explicit RowType(std::size_t bytes) {
    MPI_Type_contiguous(detail::checked_count(bytes, 1), MPI_BYTE, &type_);
    MPI_Type_commit(&type_);
  }
  ~RowType() { MPI_Type_free(&type_); }
  RowType(const RowType&) = delete;
  RowType& operator=(const RowType&) = delete;
  MPI_Datatype get() const { return type_; }

 private:
  MPI_Datatype type_ = MPI_DATATYPE_NULL;
};

std::vector<std::int64_t> exclusive_sum(const std::vector<std::int64_t>& counts) {
  std::vector<std::int64_t> at(counts.size(), 0);
  for (std::size_t r = 1; r < counts.size(); ++r) at[r] = at[r - 1] + counts[r - 1];
  return at;
}
std::terminate_handler g_previous_terminate = nullptr;

// An exception escaping on one rank: the other ranks may be waiting in a collective, so end them.
[[noreturn]] void terminate_all_ranks() {
  std::string what = "terminate called without an active exception";
  if (std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& ex) {
      what = std::string("uncaught exception: ") + ex.what();
    } catch (...) {
      what = "uncaught exception of unknown type";
    }
  }
  abort_all_ranks(what, 1);
}

bool mpi_active() {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  return initialized && !finalized;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
MpiEnvironment::MpiEnvironment(int* argc, char*** argv) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) {
    MPI_Query_thread(&provided_);
    return;
  }
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided_);
  owns_ = true;
  g_previous_terminate = std::set_terminate(terminate_all_ranks);
}

MpiEnvironment::~MpiEnvironment() {
  if (!owns_) return;
  std::set_terminate(g_previous_terminate);
  if (!mpi_active()) return;
  // Unwinding through here with an exception that only this rank has: the others may be blocked
  // in a collective and MPI_Finalize would wait for them forever.
  if (std::uncaught_exceptions() > CollectiveFailure::live_count())
    abort_all_ranks("leaving the MPI scope with an exception on this rank only", 1);
  MPI_Finalize();
}

// ---------------------------------------------------------------------------------------------
LocalError LocalError::from(std::exception_ptr error) {
  LocalError local;
  if (!error) return local;
  try {
    std::rethrow_exception(error);
  } catch (const InputError& e) {
    local = {ErrorKind::input, e.what()};
  } catch (const NumericalFailure& e) {
    local = {ErrorKind::numerical, e.what()};
  } catch (const IoError& e) {
    local = {ErrorKind::io, e.what()};
  } catch (const std::exception& e) {
    local = {ErrorKind::internal, e.what()};
  } catch (...) {
    local = {ErrorKind::internal, "unknown exception"};
  }
  return local;
}

CollectiveFailure::CollectiveFailure(int first_rank, int failed_ranks)
    : first_rank_(first_rank), failed_ranks_(failed_ranks) {
  ++g_live_collective;
}
CollectiveFailure::CollectiveFailure(const CollectiveFailure& other)
    : first_rank_(other.first_rank_), failed_ranks_(other.failed_ranks_) {
  ++g_live_collective;
}
CollectiveFailure::~CollectiveFailure() {
  --g_live_collective;
}
int CollectiveFailure::live_count() {
  return g_live_collective.load();
}

int detail::checked_count(std::size_t n, int scale) {
  const std::size_t scaled = n * static_cast<std::size_t>(scale);
  FDEM_VERIFY(scaled <= static_cast<std::size_t>(INT_MAX),
              "MPI message of " + std::to_string(scaled) + " elements exceeds the int count limit");
  return static_cast<int>(scaled);
}

std::int64_t detail::message_limit() {
  return g_message_limit.load();
}

void detail::set_message_limit(std::int64_t limit) {
  g_message_limit = limit > 0 && limit < INT_MAX ? limit : INT_MAX;
}

// ---------------------------------------------------------------------------------------------
Communicator::Communicator(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

void Communicator::barrier() const {
  MPI_Barrier(comm_);
}

int Communicator::ranks_on_this_node() const {
  MPI_Comm node = MPI_COMM_NULL;
  MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  int ranks = 1;
  MPI_Comm_size(node, &ranks);
  MPI_Comm_free(&node);
  return ranks;
}

std::int64_t Communicator::sum_over_lower_ranks(std::int64_t value) const {
  std::int64_t below = 0;
  MPI_Exscan(&value, &below, 1, MPI_INT64_T, MPI_SUM, comm_);
  return rank_ == 0 ? 0 : below;  // MPI leaves rank 0's result undefined
}

std::string Communicator::broadcast(const std::string& text, int root) const {
  std::uint64_t length = rank_ == root ? text.size() : 0;
  MPI_Bcast(&length, 1, MPI_UINT64_T, root, comm_);
  std::string result = rank_ == root ? text : std::string(length, '\0');
  const auto limit = static_cast<std::uint64_t>(detail::message_limit());
  for (std::uint64_t first = 0; first < length; first += limit)
    MPI_Bcast(result.data() + first, static_cast<int>(std::min(limit, length - first)), MPI_CHAR,
              root, comm_);
  return result;
}

std::vector<std::int64_t> Communicator::exchange_counts(
    const std::vector<std::size_t>& send_rows) const {
  FDEM_VERIFY(static_cast<int>(send_rows.size()) == size_, "one count per rank");
  const std::vector<std::int64_t> send(send_rows.begin(), send_rows.end());
  std::vector<std::int64_t> receive(static_cast<std::size_t>(size_), 0);
  MPI_Alltoall(send.data(), 1, MPI_INT64_T, receive.data(), 1, MPI_INT64_T, comm_);
  return receive;
}

void Communicator::exchange_rows(const void* send, const std::vector<std::int64_t>& send_rows,
                                 void* receive, const std::vector<std::int64_t>& receive_rows,
                                 std::size_t row_bytes) const {
  FDEM_VERIFY(
      static_cast<int>(send_rows.size()) == size_ && static_cast<int>(receive_rows.size()) == size_,
      "one count per rank");
  if (row_bytes == 0) return;  // nothing travels (every rank passes the same width)
  const std::int64_t limit = detail::message_limit();
  // A pair's rows go in the collective when at most `cap`: then a rank's collective rows total
  // at most `limit`, so every count and (compacted) displacement fits an int.
  const std::int64_t cap = limit / size_;
  const RowType row(row_bytes);
  const auto* out = static_cast<const char*>(send);
  auto* in = static_cast<char*>(receive);
  const std::vector<std::int64_t> send_at = exclusive_sum(send_rows),
                                  receive_at = exclusive_sum(receive_rows);
  const auto bytes = [&](std::int64_t rows) { return static_cast<std::size_t>(rows) * row_bytes; };
  const auto collective = [&](int r, std::int64_t rows) { return r != rank_ && rows <= cap; };

  // The collective part: at its place when every displacement fits, else through a compact copy.
  std::vector<int> sc(size_, 0), sd(size_, 0), rc(size_, 0), rd(size_, 0);
  bool send_in_place = true, receive_in_place = true;
  for (int r = 0; r < size_; ++r) {
    if (collective(r, send_rows[r])) {
      sc[r] = static_cast<int>(send_rows[r]);
      send_in_place = send_in_place && send_at[r] + send_rows[r] <= limit;
    }
    if (collective(r, receive_rows[r])) {
      rc[r] = static_cast<int>(receive_rows[r]);
      receive_in_place = receive_in_place && receive_at[r] + receive_rows[r] <= limit;
    }
  }
  std::vector<char> send_copy, receive_copy;
  const char* send_base = out;
  char* receive_base = in;
  std::int64_t at = 0;
  for (int r = 0; r < size_; ++r) {
    sd[r] = sc[r] == 0 ? 0 : static_cast<int>(send_in_place ? send_at[r] : at);
    at += sc[r];
  }
  if (!send_in_place) {
    send_copy.resize(bytes(at));
    for (int r = 0; r < size_; ++r)
      std::copy_n(out + bytes(send_at[r]), bytes(sc[r]), send_copy.data() + bytes(sd[r]));
    send_base = send_copy.data();
  }
  at = 0;
  for (int r = 0; r < size_; ++r) {
    rd[r] = rc[r] == 0 ? 0 : static_cast<int>(receive_in_place ? receive_at[r] : at);
    at += rc[r];
  }
  if (!receive_in_place) {
    receive_copy.resize(bytes(at));
    receive_base = receive_copy.data();
  }

  // Larger pairs: point-to-point chunks of at most `limit` rows, posted before the collective
  // (messages of one pair and tag arrive in the order sent).
  std::vector<MPI_Request> requests;
  const auto post = [&](bool sending, int r, std::int64_t first, std::int64_t rows) {
    for (std::int64_t k = 0; k < rows; k += limit) {
      const int n = static_cast<int>(std::min(limit, rows - k));
      requests.emplace_back();
      if (sending)
        MPI_Isend(out + bytes(first + k), n, row.get(), r, chunk_tag, comm_, &requests.back());
      else
        MPI_Irecv(in + bytes(first + k), n, row.get(), r, chunk_tag, comm_, &requests.back());
    }
  };
  for (int r = 0; r < size_; ++r)
    if (r != rank_ && !collective(r, receive_rows[r]))
      post(false, r, receive_at[r], receive_rows[r]);
  for (int r = 0; r < size_; ++r)
    if (r != rank_ && !collective(r, send_rows[r])) post(true, r, send_at[r], send_rows[r]);
  // This rank's own rows: a copy.
  FDEM_VERIFY(send_rows[rank_] == receive_rows[rank_], "a rank receives what it sends itself");
  std::copy_n(out + bytes(send_at[rank_]), bytes(send_rows[rank_]), in + bytes(receive_at[rank_]));
  MPI_Alltoallv(send_base, sc.data(), sd.data(), row.get(), receive_base, rc.data(), rd.data(),
                row.get(), comm_);
  if (!requests.empty())
    MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  if (!receive_in_place)
    for (int r = 0; r < size_; ++r)
      std::copy_n(receive_copy.data() + bytes(rd[r]), bytes(rc[r]), in + bytes(receive_at[r]));
}

std::vector<char> Communicator::exchange_rows_sparse(
    const void* send, const std::vector<std::int64_t>& send_rows, std::size_t row_bytes,
    std::vector<std::int64_t>& receive_rows) const {
  FDEM_VERIFY(static_cast<int>(send_rows.size()) == size_, "one count per rank");
  receive_rows.assign(static_cast<std::size_t>(size_), 0);
  if (row_bytes == 0) return {};
  // Two calls in a row may overlap: a rank that left call k may already send for call k + 1 to a
  // rank still receiving in call k (it cannot send for k + 2 before that rank entered k + 1's
  // barrier).  Alternating tags per communicator keeps them apart.
  static std::map<MPI_Comm, unsigned> calls;
  const int tag = sparse_tag + static_cast<int>(calls[comm_]++ % 2);
  const std::int64_t limit = detail::message_limit();
  const RowType row(row_bytes);
  const auto bytes = [&](std::int64_t rows) { return static_cast<std::size_t>(rows) * row_bytes; };
  const auto* out = static_cast<const char*>(send);
  const std::vector<std::int64_t> send_at = exclusive_sum(send_rows);
  // Synchronous sends: one completes only once it is matched, so when all of a rank's sends are
  // done, everything it sent has been received.
  std::vector<MPI_Request> sends;
  for (int r = 0; r < size_; ++r) {
    if (r == rank_) continue;
    for (std::int64_t k = 0; k < send_rows[r]; k += limit) {
      sends.emplace_back();
      MPI_Issend(out + bytes(send_at[r] + k), static_cast<int>(std::min(limit, send_rows[r] - k)),
                 row.get(), r, tag, comm_, &sends.back());
    }
  }
  std::map<int, std::vector<char>> from;  // by source rank (messages of one source in order)
  MPI_Request barrier = MPI_REQUEST_NULL;
  bool in_barrier = false;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, tag, comm_, &arrived, &status);
    if (arrived) {
      int count = 0;
      MPI_Get_count(&status, row.get(), &count);
      std::vector<char>& buffer = from[status.MPI_SOURCE];
      const std::size_t at = buffer.size();
      buffer.resize(at + bytes(count));
      MPI_Recv(buffer.data() + at, count, row.get(), status.MPI_SOURCE, tag, comm_,
               MPI_STATUS_IGNORE);
      continue;
    }
    // Nothing yet: let another process have the core (ranks may outnumber cores).
    std::this_thread::yield();
    int done = 0;
    if (!in_barrier) {
      MPI_Testall(static_cast<int>(sends.size()), sends.data(), &done, MPI_STATUSES_IGNORE);
      if (done) {
        MPI_Ibarrier(comm_, &barrier);
        in_barrier = true;
      }
    } else {
      MPI_Test(&barrier, &done, MPI_STATUS_IGNORE);
      if (done) break;  // every rank's sends were matched: nothing more is coming
    }
  }
  // What arrived, in source rank order; this rank's own rows in their place.
  std::size_t total = bytes(send_rows[rank_]);
  for (const auto& [source, buffer] : from) total += buffer.size();
  std::vector<char> received;
  received.reserve(total);
  bool own_done = false;
  const auto add_own = [&] {
    received.insert(received.end(), out + bytes(send_at[rank_]),
                    out + bytes(send_at[rank_] + send_rows[rank_]));
    receive_rows[rank_] = send_rows[rank_];
    own_done = true;
  };
  for (auto& [source, buffer] : from) {
    if (!own_done && source > rank_) add_own();
    received.insert(received.end(), buffer.begin(), buffer.end());
    receive_rows[source] = static_cast<std::int64_t>(buffer.size() / row_bytes);
    buffer = std::vector<char>{};
  }
  if (!own_done) add_own();
  return received;
}

void Communicator::allgather_rows(const void* local, const std::vector<std::int64_t>& counts,
                                  void* all, std::size_t row_bytes) const {
  if (row_bytes == 0) return;
  const std::int64_t limit = detail::message_limit();
  const RowType row(row_bytes);
  const std::vector<std::int64_t> at = exclusive_sum(counts);
  const std::int64_t total = at.back() + counts.back();
  auto* out = static_cast<char*>(all);
  const auto bytes = [&](std::int64_t rows) { return static_cast<std::size_t>(rows) * row_bytes; };
  std::vector<int> rc(size_), rd(size_);
  if (total <= limit) {  // one call, straight into place
    for (int r = 0; r < size_; ++r) {
      rc[r] = static_cast<int>(counts[r]);
      rd[r] = static_cast<int>(at[r]);
    }
    MPI_Allgatherv(local, rc[rank_], row.get(), out, rc.data(), rd.data(), row.get(), comm_);
    return;
  }
  // Rounds: each rank sends up to `share` rows per round (counts are known everywhere, so every
  // rank makes the same rounds), gathered compactly and copied into place.
  const std::int64_t share = std::max<std::int64_t>(limit / size_, 1);
  const std::int64_t most = *std::max_element(counts.begin(), counts.end());
  std::vector<char> round(bytes(share * size_));
  for (std::int64_t first = 0; first < most; first += share) {
    std::int64_t filled = 0;
    for (int r = 0; r < size_; ++r) {
      rc[r] = static_cast<int>(std::clamp<std::int64_t>(counts[r] - first, 0, share));
      rd[r] = static_cast<int>(filled);
      filled += rc[r];
    }
    MPI_Allgatherv(static_cast<const char*>(local) + bytes(std::min(first, counts[rank_])),
                   rc[rank_], row.get(), round.data(), rc.data(), rd.data(), row.get(), comm_);
    for (int r = 0; r < size_; ++r)
      std::copy_n(round.data() + bytes(rd[r]), bytes(rc[r]), out + bytes(at[r] + first));
  }
}

void Communicator::check_errors(const LocalError& local) const {
  // Fast path: one reduction of one int.  The lowest failing rank wins (deterministic).
  const int key = local.failed() ? rank_ : size_;
  int first = size_;
  MPI_Allreduce(&key, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == size_) return;

  const int failed_ranks = sum<std::int32_t>(local.failed() ? 1 : 0);
  std::int32_t kind = static_cast<std::int32_t>(local.kind);
  MPI_Bcast(&kind, 1, MPI_INT32_T, first, comm_);
  std::string message = broadcast(local.message, first);
  if (size_ > 1) {
    message = "rank " + std::to_string(first) + ": " + message;
    if (failed_ranks > 1)
      message += " (and " + std::to_string(failed_ranks - 1) + " more rank" +
                 (failed_ranks > 2 ? "s" : "") + " failed)";
  }
  switch (static_cast<ErrorKind>(kind)) {
    case ErrorKind::input:
      throw CollectiveInputError(message, first, failed_ranks);
    case ErrorKind::numerical:
      throw CollectiveNumericalFailure(message, first, failed_ranks);
    case ErrorKind::io:
      throw CollectiveIoError(message, first, failed_ranks);
    default:
      throw CollectiveInternalError(message, first, failed_ranks);
  }
}

void Communicator::abort_all(const std::string& message, int code) const {
  std::fprintf(stderr, "fdem: rank %d of %d: %s\n", rank_, size_, message.c_str());
  std::fflush(stderr);
  std::fflush(stdout);
  MPI_Abort(comm_, code == 0 ? 1 : code);
  std::_Exit(code == 0 ? 1 : code);  // MPI_Abort does not return; this keeps [[noreturn]] honest
}

void abort_all_ranks(const std::string& message, int code) {
  if (mpi_active()) Communicator::world().abort_all(message, code);
  std::fprintf(stderr, "fdem: %s\n", message.c_str());
  std::fflush(stderr);
  std::_Exit(code == 0 ? 1 : code);
}

void mark_phase(CommPhase phase) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised) MPI_Pcontrol(100 + static_cast<int>(phase));
}

}  // namespace fdem
