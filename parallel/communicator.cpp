#include "parallel/communicator.hpp"

#include <atomic>
#include <climits>
#include <cstdio>
#include <cstdlib>

namespace fdem {

namespace {

std::atomic<int> g_live_collective{0};
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

std::int64_t Communicator::exclusive_sum(std::int64_t value) const {
  std::int64_t below = 0;
  MPI_Exscan(&value, &below, 1, MPI_INT64_T, MPI_SUM, comm_);
  return rank_ == 0 ? 0 : below;  // MPI leaves rank 0's result undefined
}

std::string Communicator::broadcast(const std::string& text, int root) const {
  std::uint64_t length = rank_ == root ? text.size() : 0;
  MPI_Bcast(&length, 1, MPI_UINT64_T, root, comm_);
  std::string result = rank_ == root ? text : std::string(length, '\0');
  MPI_Bcast(result.data(), detail::checked_count(length, 1), MPI_CHAR, root, comm_);
  return result;
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
