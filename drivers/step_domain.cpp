#include "drivers/step_domain.hpp"

#include "core/error.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

namespace {

class OneRankDomain final : public StepDomain {
 public:
  bool redistributes() const override { return false; }
  void sum(std::vector<double>&) const override {}
  bool any(bool local) const override { return local; }
  std::vector<char> gather(const std::vector<char>& mine) const override { return mine; }
  std::vector<char> send_to_holders(const std::vector<GlobalId>&, const std::vector<char>&,
                                    std::size_t) const override {
    return {};  // no copies elsewhere
  }
  void run_collectively(const std::function<void()>& check) const override { check(); }
  void redistribute(Model&, TravellingState&, const std::vector<double>&, double) override {
    FDEM_VERIFY(false, "one rank never redistributes");
  }
  void start_halo_exchange(const NodeArrays&) override {}
  void finish_halo_exchange(NodeArrays&) override {}
};

class DistributedDomain final : public StepDomain {
 public:
  DistributedDomain(const Communicator& comm, Distribution& distribution)
      : comm_(comm), distribution_(distribution) {}
  bool redistributes() const override { return true; }
  void sum(std::vector<double>& values) const override { comm_.sum_in_place(values); }
  bool any(bool local) const override { return comm_.max(std::int32_t{local}) > 0; }
  std::vector<char> gather(const std::vector<char>& mine) const override {
    return comm_.allgatherv(mine);
  }
  std::vector<char> send_to_holders(const std::vector<GlobalId>& tets,
                                    const std::vector<char>& records,
                                    std::size_t record_bytes) const override {
    return distribution_.send_to_holders(tets, records, record_bytes);
  }
  void run_collectively(const std::function<void()>& check) const override {
    comm_.run_collectively(check);
  }
  void redistribute(Model& model, TravellingState& state, const std::vector<double>& cost,
                    double busy_seconds) override {
    finish_halo_exchange(model.nodes);  // migration moves the positions of the ghosts too
    mark_phase(CommPhase::redistribution);
    distribution_.redistribute(model, state, cost, busy_seconds);
    mark_phase(CommPhase::step);
  }
  void start_halo_exchange(const NodeArrays& nodes) override {
    distribution_.start_halo_exchange(nodes);
    in_flight_ = true;
  }
  void finish_halo_exchange(NodeArrays& nodes) override {
    if (!in_flight_) return;
    distribution_.finish_halo_exchange(nodes);
    in_flight_ = false;
  }

 private:
  const Communicator& comm_;
  Distribution& distribution_;
  bool in_flight_ = false;  // ghost exchange posted, not yet completed
};

}  // namespace

std::unique_ptr<StepDomain> one_rank_domain() {
  return std::make_unique<OneRankDomain>();
}

std::unique_ptr<StepDomain> distributed_domain(const Communicator& comm,
                                               Distribution& distribution) {
  return std::make_unique<DistributedDomain>(comm, distribution);
}

}  // namespace fdem
