// Verification suite: every reference problem of the design notes (docs/references.md) that the
// engine supports, run at several mesh sizes h, time-step fractions Δt/Δt_crit and penalty ratios
// p/E. Each run records its wall time and the error of each measured quantity against its reference
// value, with the pass/fail tolerance of that quantity: the "run time against error" curves of
// docs/verification.md.
//
// Sweeps: every problem has a base setting (its finest: the most accurate one the suite runs) and
// varies one parameter at a time from it; the CSV's `sweep` column says which (base rows belong to
// every series).  --quick runs one setting per problem: the coarsest mesh of its sweep at the
// base step and penalty.
//
// Usage: bench_verification [--quick] [--csv PATH] [--only NAME[,NAME...]] [--list]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/materials.hpp"
#include "core/model_builder.hpp"
#include "core/tet_kernels.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "drivers/simulation.hpp"
#include "fracture/joint_stage.hpp"
#include "verification_suite/suite.hpp"

using namespace fdem;
using namespace fdem::verification_suite;

namespace {

struct Problem {
  std::string name;       // short id, used in file names
  std::string reference;  // docs/references.md item
  Setting base;
  std::vector<double> h, dt_fraction, penalty_ratio;  // the values swept (besides the base)
  std::function<std::vector<Measure>(const Setting&)> run;
};

struct Row {
  std::string problem, sweep;
  Setting setting;
  double wall = 0;
  Measure m;
  bool pass() const { return std::isfinite(m.error) && m.error <= m.tolerance; }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ------------------------------------------------------------------------------------------------
// The problems and their sweeps
// ------------------------------------------------------------------------------------------------
std::vector<Problem> problems() {
  std::vector<Problem> p;
  // name, reference, base {h, dt_fraction, penalty_ratio}, h sweep, dt sweep, penalty sweep, run
  p.push_back({"stopped_bar",
               "1",
               {0.02 / 160, 0.9, 0},
               {0.02 / 40, 0.02 / 80},
               {0.3, 0.6},
               {},
               stopped_bar});
  p.push_back({"two_bar_impact",
               "2",
               {0.5 / 200, 0.5, 10},
               {0.5 / 50, 0.5 / 100},
               {0.25},
               {1, 100},
               two_bar_impact});
  p.push_back({"tet_tet_impact", "3", {0, 0.05, 10}, {}, {0.1, 0.2}, {1, 100}, tet_tet_impact});
  p.push_back(
      {"spinning_cube", "4b", {1.0 / 8, 0.45, 0}, {1.0 / 2, 1.0 / 4}, {0.9}, {}, spinning_cube});
  p.push_back(
      {"axial_frequency", "5", {0.025, 0.45, 0}, {0.1, 0.05}, {0.7, 0.9}, {}, axial_frequency});
  p.push_back({"bending_frequency",
               "5",
               {0.0125, 0.9, 0},
               {0.1, 0.05, 0.025},
               {0.45},
               {},
               bending_frequency});
  p.push_back({"incline", "6", {0.125, 0.5, 10}, {0.5, 0.25}, {0.9}, {100}, incline});
  p.push_back({"oblique_impact", "7", {0.05, 0.5, 10}, {0.2, 0.1}, {0.25}, {100}, oblique_impact});
  p.push_back(
      {"stacked_blocks", "8", {0.1, 0.5, 100}, {}, {0.25, 0.9}, {3, 10, 30}, stacked_blocks});
  p.push_back({"cohesive_layer", "10", {0.025, 0.35, 0}, {0.1, 0.05}, {0.7}, {}, cohesive_layer});
  p.push_back({"dry_joint_shear", "12", {0.05, 0.35, 0}, {0.1}, {0.7}, {}, dry_joint_shear});
  p.push_back({"uniaxial_compression",
               "14",
               {0.05, 0.5, 10},
               {0.1, 0.025},
               {0.9},
               {1, 30},
               uniaxial_compression});
  return p;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, list = false;
  std::string csv_path = "verification.csv";
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick")
      quick = true;
    else if (arg == "--list")
      list = true;
    else if (arg == "--csv" && i + 1 < argc)
      csv_path = argv[++i];
    else if (arg == "--only" && i + 1 < argc)
      only = split(argv[++i], ',');
    else {
      std::cerr << "usage: bench_verification [--quick] [--csv PATH] [--only NAME[,NAME...]] "
                   "[--list]\n";
      return 2;
    }
  }
  const std::vector<Problem> all = problems();
  if (list) {
    for (const Problem& p : all)
      std::cout << p.name << " (docs/references.md " << p.reference << ")\n";
    return 0;
  }
  std::ofstream csv(csv_path);
  if (!csv) {
    std::cerr << "cannot write " << csv_path << "\n";
    return 2;
  }
  csv << "problem,quantity,h,dt_fraction,penalty_ratio,wall_seconds,value,reference,error,"
         "tolerance,pass,sweep\n";
  csv.precision(10);
  std::printf("%-22s %-8s %-34s %9s %6s %6s %8s %12s %12s %10s %9s %s\n", "problem", "sweep",
              "quantity", "h (m)", "dt/dtc", "p/E", "wall s", "value", "reference", "error",
              "tolerance", "pass");
  int failed_runs = 0;
  for (const Problem& problem : all) {
    if (!only.empty() && std::find(only.begin(), only.end(), problem.name) == only.end()) continue;
    // (sweep name, setting): base first, then one parameter at a time.
    std::vector<std::pair<std::string, Setting>> runs;
    auto add_series = [&](const std::string& name, const std::vector<double>& values,
                          double Setting::*field) {
      for (double value : values) {
        Setting s = problem.base;
        s.*field = value;
        runs.push_back({name, s});
      }
    };
    if (quick) {  // the cheap end: coarsest mesh of the sweep, base step and penalty
      Setting s = problem.base;
      for (double h : problem.h) s.h = std::max(s.h, h);
      runs.push_back({"quick", s});
    } else {
      runs.push_back({"base", problem.base});
      add_series("h", problem.h, &Setting::h);
      add_series("dt_fraction", problem.dt_fraction, &Setting::dt_fraction);
      add_series("penalty_ratio", problem.penalty_ratio, &Setting::penalty_ratio);
    }
    for (const auto& [sweep, setting] : runs) {
      std::vector<Measure> measures;
      const auto t0 = std::chrono::steady_clock::now();
      std::string failure;
      try {
        measures = problem.run(setting);
      } catch (const std::exception& e) {
        failure = e.what();
      }
      const double wall = seconds_since(t0);
      if (!failure.empty()) {
        ++failed_runs;
        std::printf("%-22s %-8s run failed after %.1f s: %s\n", problem.name.c_str(), sweep.c_str(),
                    wall, failure.c_str());
        measures.push_back({"run_failed", std::nan(""), 0, std::nan(""), 0});
      }
      for (const Measure& m : measures) {
        Row row{problem.name, sweep, setting, wall, m};
        std::printf("%-22s %-8s %-34s %9.3g %6.3g %6.3g %8.2f %12.5g %12.5g %10.3g %9.3g %s\n",
                    problem.name.c_str(), sweep.c_str(), m.quantity.c_str(), setting.h,
                    setting.dt_fraction, setting.penalty_ratio, wall, m.value, m.reference, m.error,
                    m.tolerance, row.pass() ? "yes" : "NO");
        csv << problem.name << ',' << m.quantity << ',' << setting.h << ',' << setting.dt_fraction
            << ',' << setting.penalty_ratio << ',' << wall << ',' << m.value << ',' << m.reference
            << ',' << m.error << ',' << m.tolerance << ',' << (row.pass() ? "yes" : "no") << ','
            << sweep << '\n';
      }
      std::fflush(stdout);
      csv.flush();
    }
  }
  return failed_runs > 0 ? 1 : 0;
}
