// The verification suite's shared parts (bench_verification.cpp runs it): a sweep's setting, a
// measured quantity against its reference, scene helpers, and the reference problems, each a
// function from a setting to its measures (elastic_problems.cpp, contact_fracture_problems.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/model_builder.hpp"
#include "drivers/scene_builders.hpp"

namespace fdem::verification_suite {

// ------------------------------------------------------------------------------------------------
// Suite plumbing
// ------------------------------------------------------------------------------------------------

// One point of a sweep.  h: characteristic element size (m; 0 where the mesh is fixed),
// dt_fraction: Δt/Δt_crit (time.safety), penalty_ratio: contact penalty p/E (0: not used).
struct Setting {
  double h = 0, dt_fraction = 0.5, penalty_ratio = 0;
};

// A measured quantity: `error` is what the tolerance applies to (relative error, or an absolute
// error for quantities whose reference is 0, such as drifts and balance errors).
struct Measure {
  std::string quantity;
  double value = 0, reference = 0, error = 0, tolerance = 0;
};

inline Measure relative(const std::string& q, double value, double reference, double tolerance) {
  return {q, value, reference, std::abs(value - reference) / std::abs(reference), tolerance};
}
inline Measure absolute(const std::string& q, double value, double reference, double tolerance) {
  return {q, value, reference, std::abs(value - reference), tolerance};
}

// ------------------------------------------------------------------------------------------------
// Scene helpers: drivers/scene_builders.hpp (shared with the verification tests), and these
// ------------------------------------------------------------------------------------------------

inline void set_penalty(MaterialSpec& m, double penalty_ratio) {
  if (penalty_ratio <= 0) return;  // automatic (10 E)
  m.contact.auto_penalty = false;
  m.contact.penalty = penalty_ratio * m.elastic.young;
}

inline Scene basic_scene(double end_time, double dt_fraction) {
  Scene s = builders::basic_scene(end_time);
  s.time.safety = dt_fraction;
  return s;
}

inline int cells_for(double length, double h) {
  return std::max(1, int(std::lround(length / h)));
}

// Mean of coordinate k of the nodes of `body` whose reference coordinate k equals `at` (m).
inline double face_position(const Model& model, int body, int k, double at,
                            bool displacement = false) {
  double sum = 0;
  int n = 0;
  for (LocalIndex i = 0; i < model.nodes.size(); ++i)
    if (model.pieces[model.nodes.piece[i]].body == body &&
        std::abs(model.nodes.x0(i)[k] - at) < 1e-9) {
      sum += model.nodes.x[3 * i + k] - (displacement ? model.nodes.x0(i)[k] : 0.0);
      ++n;
    }
  return sum / n;
}

// Zero crossings of a sampled signal, linearly interpolated (s).
struct CrossingCounter {
  std::vector<double> times;
  double previous = 0, previous_time = 0;
  bool started = false;
  void add(double t, double value) {
    if (started && (value < 0) != (previous < 0) && previous != value)
      times.push_back(previous_time + (t - previous_time) * previous / (previous - value));
    previous = value;
    previous_time = t;
    started = true;
  }
  // Frequency from the mean spacing of crossings (two per period), Hz; 0 if too few.
  double frequency() const {
    if (times.size() < 3) return 0;
    return 0.5 * (times.size() - 1) / (times.back() - times.front());
  }
};

// The problems (docs/references.md items 1–8, 10, 12, 14).
std::vector<Measure> stopped_bar(const Setting& s);
std::vector<Measure> two_bar_impact(const Setting& s);
std::vector<Measure> tet_tet_impact(const Setting& s);
std::vector<Measure> spinning_cube(const Setting& s);
std::vector<Measure> axial_frequency(const Setting& s);
std::vector<Measure> bending_frequency(const Setting& s);
std::vector<Measure> incline(const Setting& s);
std::vector<Measure> oblique_impact(const Setting& s);
std::vector<Measure> stacked_blocks(const Setting& s);
std::vector<Measure> cohesive_layer(const Setting& s);
std::vector<Measure> dry_joint_shear(const Setting& s);
std::vector<Measure> uniaxial_compression(const Setting& s);

}  // namespace fdem::verification_suite
