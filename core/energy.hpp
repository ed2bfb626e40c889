// Energy bookkeeping: E_kin + U + E_grav + U_contact + U_joint + D_friction + D_fracture +
// D_damping + D_boundary − W_ext = E_0 (D_boundary: absorbing boundaries' dashpots).  Work and
// dissipation terms grow by increments that cover [t_n − dt/2, t_n + dt/2]; the value reported at
// t_n takes half of the latest increment so every term refers to t_n.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace fdem {

struct EnergyTerms {
  double kinetic = 0.0, strain = 0.0, gravity = 0.0, contact = 0.0, joint = 0.0;
  double dissipated_fracture = 0.0, dissipated_friction = 0.0, dissipated_damping = 0.0;
  double dissipated_boundary = 0.0;  // J: absorbing boundaries (core/absorbing_boundary)
  double external_work = 0.0;

  double total() const {
    return kinetic + strain + gravity + contact + joint + dissipated_fracture +
           dissipated_friction + dissipated_damping + dissipated_boundary - external_work;
  }
  // The largest magnitude among the terms: the scale that the balance error is measured against.
  double scale() const {
    return std::max({std::abs(kinetic), std::abs(strain), std::abs(gravity), std::abs(contact),
                     std::abs(joint), dissipated_fracture, dissipated_friction, dissipated_damping,
                     dissipated_boundary, std::abs(external_work)});
  }
};

// Work of a force by the trapezoid rule, W(t_n) = Σ_k ½(F_k + F_k+1)·(x_k+1 − x_k).  Step n
// supplies F_n·(x_n − x_n−1)/2 ("before") and F_n·(x_n+1 − x_n)/2 ("after"); with the kinetic
// energy taken as ½m·v_n−½·v_n+½ this makes the central-difference balance exact for constant and
// linear forces.
struct WorkAccumulator {
  double through_previous = 0.0;  // Σ_{k<n} (before_k + after_k)
  double first_before = 0.0;
  bool started = false;
  // Adds step n's halves and returns the work done up to t_n.
  double add(double before, double after) {
    if (!started) {
      first_before = before;
      started = true;
    }
    const double at_n = through_previous + before - first_before;
    through_previous += before + after;
    return at_n;
  }
};

class EnergyLedger {
 public:
  // Records the state at t_n; the first call fixes E_0.
  void record(const EnergyTerms& terms) {
    current_ = terms;
    if (!has_initial_) {
      initial_total_ = terms.total();
      has_initial_ = true;
    }
    peak_scale_ = std::max(peak_scale_, terms.scale());
  }
  const EnergyTerms& current() const { return current_; }
  double initial_total() const { return initial_total_; }
  // |E(t) − E_0| / (largest term seen so far); 0 while nothing has moved.
  double balance_error() const {
    return peak_scale_ > 0.0 ? std::abs(current_.total() - initial_total_) / peak_scale_ : 0.0;
  }

  WorkAccumulator damping, friction, fracture, external, gravity, boundary;

  // Restart: every value as (name, number), and back (`value` returns the saved number of a name).
  std::vector<std::pair<std::string, double>> saved_state() const {
    std::vector<std::pair<std::string, double>> out = {
        {"kinetic", current_.kinetic},
        {"strain", current_.strain},
        {"gravity", current_.gravity},
        {"contact", current_.contact},
        {"joint", current_.joint},
        {"dissipated_fracture", current_.dissipated_fracture},
        {"dissipated_friction", current_.dissipated_friction},
        {"dissipated_damping", current_.dissipated_damping},
        {"dissipated_boundary", current_.dissipated_boundary},
        {"external_work", current_.external_work},
        {"initial_total", initial_total_},
        {"peak_scale", peak_scale_},
        {"has_initial", has_initial_ ? 1.0 : 0.0}};
    const std::pair<const char*, const WorkAccumulator*> accumulators[] = {
        {"damping", &damping},   {"friction", &friction}, {"fracture", &fracture},
        {"external", &external}, {"gravity", &gravity},   {"boundary", &boundary}};
    for (const auto& [name, a] : accumulators) {
      out.emplace_back(std::string("work_") + name + "_through_previous", a->through_previous);
      out.emplace_back(std::string("work_") + name + "_first_before", a->first_before);
      out.emplace_back(std::string("work_") + name + "_started", a->started ? 1.0 : 0.0);
    }
    return out;
  }
  // `optional(name, fallback)`: a value that checkpoints from before it existed lack (the
  // absorbing boundaries' terms: 0 then, as no such boundary existed).
  void restore(const std::function<double(const std::string&)>& value,
               const std::function<double(const std::string&, double)>& optional) {
    current_.kinetic = value("kinetic");
    current_.strain = value("strain");
    current_.gravity = value("gravity");
    current_.contact = value("contact");
    current_.joint = value("joint");
    current_.dissipated_fracture = value("dissipated_fracture");
    current_.dissipated_friction = value("dissipated_friction");
    current_.dissipated_damping = value("dissipated_damping");
    current_.dissipated_boundary = optional("dissipated_boundary", 0.0);
    current_.external_work = value("external_work");
    initial_total_ = value("initial_total");
    peak_scale_ = value("peak_scale");
    has_initial_ = value("has_initial") != 0.0;
    const std::pair<const char*, WorkAccumulator*> accumulators[] = {
        {"damping", &damping},   {"friction", &friction}, {"fracture", &fracture},
        {"external", &external}, {"gravity", &gravity},   {"boundary", &boundary}};
    for (const auto& [name, a] : accumulators) {
      const std::string w = std::string("work_") + name;
      const bool old = a == &boundary;  // absent from older checkpoints
      a->through_previous =
          old ? optional(w + "_through_previous", 0.0) : value(w + "_through_previous");
      a->first_before = old ? optional(w + "_first_before", 0.0) : value(w + "_first_before");
      a->started = (old ? optional(w + "_started", 0.0) : value(w + "_started")) != 0.0;
    }
  }

 private:
  EnergyTerms current_;
  double initial_total_ = 0.0;
  double peak_scale_ = 0.0;
  bool has_initial_ = false;
};

}  // namespace fdem
