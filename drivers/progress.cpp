#include "drivers/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace fdem {

namespace {

// Wall-clock durations in a log: h:mm:ss (a batch job runs for hours).
std::string clock_text(double seconds) {
  const long s = std::lround(std::max(0.0, std::min(seconds, 1e9)));
  char text[32];
  std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return text;
}

double rate_of(const ProgressSample& s) {
  return s.step / std::max(s.wall, 1e-9);
}

}  // namespace

bool PlainProgressRule::due(long step, long total, double wall, bool last) {
  const long percent = total > 0 ? static_cast<long>((100.0 * step) / total) : 100;
  const bool next_percent = percent > percent_ && wall - last_wall_ >= min_interval;
  if (!(last || next_percent || wall - last_wall_ >= heartbeat)) return false;
  percent_ = percent;
  last_wall_ = wall;
  return true;
}

std::string plain_progress_line(const ProgressSample& s) {
  const double rate = rate_of(s);
  const double eta = (s.total_steps - s.step) / std::max(rate, 1e-9);
  char text[256];
  std::snprintf(text, sizeof text,
                "step %ld/%ld (%.1f %%)  t = %.6g s  dt = %.3g s  energy error %.2e  "
                "%.3g steps/s  wall %s  ETA %s\n",
                s.step, s.total_steps, 100.0 * s.step / std::max(s.total_steps, 1L), s.time,
                s.time_step, s.energy_error, rate, clock_text(s.wall).c_str(),
                clock_text(eta).c_str());
  return text;
}

bool ProgressReport::stderr_is_terminal() {
  return isatty(fileno(stderr)) == 1;
}

void ProgressReport::after_step(const ProgressSample& s, bool last) {
  if (quiet_) return;
  if (!terminal_) {
    if (rule_.due(s.step, s.total_steps, s.wall, last)) {
      std::fputs(plain_progress_line(s).c_str(), out_);
      std::fflush(out_);
    }
    return;
  }
  if (!(last || s.wall - last_terminal_ > 0.5)) return;
  last_terminal_ = s.wall;
  const double rate = rate_of(s);
  std::fprintf(
      out_, "\rstep %ld/%ld  t = %.4g s  %5.1f %%  %.3g steps/s  ETA %.1f s  energy error %.2e   ",
      s.step, s.total_steps, s.time, 100.0 * s.step / std::max(s.total_steps, 1L), rate,
      (s.total_steps - s.step) / std::max(rate, 1e-9), s.energy_error);
  open_line_ = !last;
  if (last) std::fprintf(out_, "\n");
}

void ProgressReport::end_line() {
  if (quiet_ || !open_line_) return;
  std::fprintf(out_, "\n");
  open_line_ = false;
}

}  // namespace fdem
