// The ranks that step one model together, as the time step sees them: sums over the ranks, the
// exchange of a step's records, collective checks, the ghost exchange and the re-balancing
// migration.  One rank is the trivial domain (every collective is the identity, nothing moves); N
// ranks wrap a Communicator and a Distribution (parallel/).  Serial and distributed runs take the
// same path through Simulation::step: only the domain differs.
#pragma once

#include <cstring>
#include <functional>
#include <memory>
#include <type_traits>
#include <vector>

#include "core/model.hpp"

namespace fdem {

class Communicator;
class Distribution;
struct TravellingState;

class StepDomain {
 public:
  virtual ~StepDomain() = default;
  // Whether redistribute() moves anything (one rank: never).
  virtual bool redistributes() const = 0;
  // Element-wise sum over the ranks, in place: the step's one blocking reduction.
  virtual void sum(std::vector<double>& values) const = 0;
  // Whether `local` holds on any rank (a blocking reduction: start-up and restarts only).
  virtual bool any(bool local) const = 0;
  // Every rank's bytes, concatenated in rank order (a blocking collective).
  virtual std::vector<char> gather(const std::vector<char>& mine) const = 0;
  // Collective, neighbour-only: record i (`record_bytes` bytes) about owned tet `tets[i]` goes to
  // every other rank that holds a copy of that tet; returns what arrived (one rank: nothing).
  virtual std::vector<char> send_to_holders(const std::vector<GlobalId>& tets,
                                            const std::vector<char>& records,
                                            std::size_t record_bytes) const = 0;
  // Runs `check` on every rank; what it throws on some ranks is thrown on every rank.
  virtual void run_collectively(const std::function<void()>& check) const = 0;
  // Collective: re-balances, migrates the tets with `state`, rebuilds the halo
  // (parallel/distribution.hpp).  `cost`: per local tet, its contact cost in tet units;
  // `busy_seconds`: this rank's compute time since the last call (what re-partitioning gains).
  virtual void redistribute(Model& model, TravellingState& state, const std::vector<double>& cost,
                            double busy_seconds) = 0;
  // Split-phase ghost exchange of positions and velocities; finish() does nothing when no
  // exchange is in flight.
  virtual void start_halo_exchange(const NodeArrays& nodes) = 0;
  virtual void finish_halo_exchange(NodeArrays& nodes) = 0;
};

std::unique_ptr<StepDomain> one_rank_domain();
// N ranks: `comm` and `distribution` must outlive the domain.
std::unique_ptr<StepDomain> distributed_domain(const Communicator& comm,
                                               Distribution& distribution);

namespace detail {
// Trivially copyable records as the bytes the domain moves, and back.
template <class T>
std::vector<char> record_bytes(const std::vector<T>& records) {
  static_assert(std::is_trivially_copyable_v<T>, "records travel as bytes");
  std::vector<char> bytes(records.size() * sizeof(T));
  if (!bytes.empty()) std::memcpy(bytes.data(), records.data(), bytes.size());
  return bytes;
}
template <class T>
std::vector<T> records_of(const std::vector<char>& bytes) {
  std::vector<T> records(bytes.size() / sizeof(T));
  if (!records.empty()) std::memcpy(records.data(), bytes.data(), records.size() * sizeof(T));
  return records;
}
}  // namespace detail

// The records of every rank (trivially copyable values), concatenated in rank order.
template <class T>
std::vector<T> gather_records(const StepDomain& domain, const std::vector<T>& mine) {
  return detail::records_of<T>(domain.gather(detail::record_bytes(mine)));
}

// Record i (trivially copyable) about owned tet `tets[i]` to every other rank holding a copy of
// that tet; returns the records that arrived.
template <class T>
std::vector<T> records_to_holders(const StepDomain& domain, const std::vector<GlobalId>& tets,
                                  const std::vector<T>& records) {
  return detail::records_of<T>(
      domain.send_to_holders(tets, detail::record_bytes(records), sizeof(T)));
}

}  // namespace fdem
