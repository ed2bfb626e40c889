// The progress report of a run (rank 0, stderr).  On a terminal one line is rewritten in place
// with '\r' at most twice a second, as before.  Anywhere else — a batch job's log, a pipe, a file
// under mpirun — '\r' would pile every update into one line of many kilobytes, so the report is
// plain lines instead, like LAMMPS thermo output:
//   - one when the run has done another whole 1 % of its steps, but at most one per 10 s of wall
//     time (a fast run does not flood the log: at most 100 such lines);
//   - one at least every 10 min of wall time whatever the progress (a slow run, or a stuck one,
//     still shows its state);
//   - one at the last step.
// So a log holds at most 101 + wall/600 s lines, each with step, % done, simulated time, time
// step, energy balance error, steps/s, wall time and ETA.
#pragma once

#include <cstdio>
#include <string>

namespace fdem {

struct ProgressSample {
  long step = 0, total_steps = 1;
  double time = 0.0;          // simulated (s)
  double time_step = 0.0;     // s
  double energy_error = 0.0;  // balance error (fraction)
  double wall = 0.0;          // s since the run started
};

// When the plain (non-terminal) report prints: a pure rule, tested on its own.
class PlainProgressRule {
 public:
  static constexpr double min_interval = 10.0;  // s of wall time between percent lines
  static constexpr double heartbeat = 600.0;    // s of wall time: a line at least this often

  // Whether a line is due after step `step` of `total`, `wall` s into the run; remembers it.
  bool due(long step, long total, double wall, bool last);

 private:
  long percent_ = 0;        // whole percent done at the last line
  double last_wall_ = 0.0;  // s at the last line
};

// One plain progress line (no '\r', ends with '\n').
std::string plain_progress_line(const ProgressSample& s);

class ProgressReport {
 public:
  // terminal: `out` is a terminal ('\r' line); quiet: print nothing.
  ProgressReport(bool quiet, bool terminal, std::FILE* out = stderr)
      : quiet_(quiet), terminal_(terminal), out_(out) {}
  // Whether stderr is a terminal.
  static bool stderr_is_terminal();

  // After each step (`last`: the run's final step).
  void after_step(const ProgressSample& s, bool last);
  // Ends an unfinished '\r' line before other output (an interruption, a failure).
  void end_line();

 private:
  bool quiet_, terminal_;
  std::FILE* out_;
  bool open_line_ = false;      // a '\r' line without its '\n' yet
  double last_terminal_ = 0.0;  // wall s of the last '\r' line
  PlainProgressRule rule_;
};

}  // namespace fdem
