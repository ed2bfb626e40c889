// What the stages of one time step report on this rank, and the values the step sums over the
// ranks in its one reduction (Simulation::step, drivers/simulation_step.cpp).
#pragma once

#include <array>

#include "contact/contact_stage.hpp"
#include "contact/detection.hpp"
#include "core/dynamics.hpp"
#include "core/time_step.hpp"
#include "fracture/joint_stage.hpp"

namespace fdem {

// Counts of ranks (or of joints) that saw something that steers or stops the run: summed over
// the ranks with the energy terms, so that every rank decides alike without another collective.
struct StepFlags {
  double nonfinite_velocity = 0.0;  // a velocity became NaN or infinite
  double inverted_tet = 0.0;        // a tet inverted or has NaN corners
  double interrupted = 0.0;         // a signal arrived (drivers/interrupt.hpp)
  double step_too_large = 0.0;      // the minimum-step guard fired
  double detection_due = 0.0;       // a node went more than buffer/2 since the last detection
  double tunnelling = 0.0;          // a node went further than the thinnest element in one step
  double broken_joints = 0.0;       // joints this rank reports broken in this step
  double bodies_cracked = 0.0;      // ... of which in a body none of whose joints had broken
};

struct StepRecord {
  InternalForceSummary forces;
  JointStepSummary joints;
  ContactForceSummary contact;
  ContactWork contact_after;  // the "after" halves of friction and dashpot work (v_n+½ known)
  IntegrationSummary motion;
  double boundary_before = 0.0, boundary_after = 0.0;  // J, absorbing dashpots' dissipation
  double surface_power_before = 0.0;                   // W, surface loads with v(t_n − dt/2)
  double surface_force = 0.0;  // N, Σ|F| of the surface loads' corner forces (quasi-static runs)
  CriticalStep deformed;       // stable step of the deformed mesh, when the guard checked it
  StepFlags flags;
};

// Every value of a StepRecord that the step sums over the ranks, each listed once.
inline std::array<double*, 37> summed_values(StepRecord& r) {
  double* p_before = r.motion.momentum_before.data();
  double* p_after = r.motion.momentum_after.data();
  StepFlags& f = r.flags;
  return {&r.forces.strain_energy,
          &r.forces.damping_power,
          &r.joints.stored_energy,
          &r.joints.fracture_dissipated,
          &r.joints.friction_dissipated,
          &r.contact.energy,
          &r.contact.friction_spring_energy,
          &r.contact.work_before.friction,
          &r.contact.work_before.damping,
          &r.contact_after.friction,
          &r.contact_after.damping,
          &r.motion.kinetic_energy,
          &r.motion.kinetic_energy_half_step,
          &r.motion.constraint_work_before,
          &r.motion.constraint_work_after,
          &r.motion.damping_work_before,
          &r.motion.damping_work_after,
          &r.motion.unbalanced_force,
          &r.motion.support_force,
          &r.surface_force,
          &r.motion.mass,
          p_before,
          p_before + 1,
          p_before + 2,
          p_after,
          p_after + 1,
          p_after + 2,
          &r.boundary_before,
          &r.boundary_after,
          &f.nonfinite_velocity,
          &f.inverted_tet,
          &f.interrupted,
          &f.step_too_large,
          &f.detection_due,
          &f.tunnelling,
          &f.broken_joints,
          &f.bodies_cracked};
}

}  // namespace fdem
