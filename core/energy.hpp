// Energy bookkeeping: E_kin + U + E_grav + U_contact + U_joint + D_friction + D_fracture +
// D_damping − W_ext = E_0.  Work and dissipation terms grow by increments that cover [t_n − dt/2,
// t_n + dt/2]; the value reported at t_n takes half of the latest increment so every term refers to
// t_n.
#pragma once

#include <algorithm>
#include <cmath>

namespace fdem {

struct EnergyTerms {
  double kinetic = 0.0, strain = 0.0, gravity = 0.0, contact = 0.0, joint = 0.0;
  double dissipated_fracture = 0.0, dissipated_friction = 0.0, dissipated_damping = 0.0;
  double external_work = 0.0;

  double total() const {
    return kinetic + strain + gravity + contact + joint + dissipated_fracture +
           dissipated_friction + dissipated_damping - external_work;
  }
  // The largest magnitude among the terms: the scale that the balance error is measured against.
  double scale() const {
    return std::max({std::abs(kinetic), std::abs(strain), std::abs(gravity), std::abs(contact),
                     std::abs(joint), dissipated_fracture, dissipated_friction, dissipated_damping,
                     std::abs(external_work)});
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

  WorkAccumulator damping, friction, fracture, external, gravity;

 private:
  EnergyTerms current_;
  double initial_total_ = 0.0;
  double peak_scale_ = 0.0;
  bool has_initial_ = false;
};

}  // namespace fdem
