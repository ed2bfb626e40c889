// The progress report: '\r' only on a terminal; in a log, plain lines at a bounded rate (every
// 1 % of the steps but at most one per 10 s, at least one per 10 min, and the last step).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <string>

#include "cli_test_support.hpp"
#include "drivers/progress.hpp"

using fdem::PlainProgressRule;
using fdem::ProgressReport;
using fdem::ProgressSample;
using fdem_test::read_text;
using fdem_test::TempDir;
using fdem_test::write_text;

namespace {

// Steps a run of `total` steps taking `seconds` of wall time at a steady rate through a report
// writing into a file; returns what it wrote.
std::string drive(bool terminal, long total, double seconds) {
  std::FILE* file = std::tmpfile();
  REQUIRE(file);
  {
    ProgressReport report(false, terminal, file);
    for (long step = 1; step <= total; ++step)
      report.after_step({step, total, 1e-6 * step, 1e-6, 1e-5, seconds * step / total},
                        step == total);
  }
  std::string text;
  std::rewind(file);
  for (int c; (c = std::fgetc(file)) != EOF;) text += static_cast<char>(c);
  std::fclose(file);
  return text;
}

long count(const std::string& text, char c) {
  return static_cast<long>(std::count(text.begin(), text.end(), c));
}

}  // namespace

TEST_CASE("plain progress: every 1 %, at most one line per 10 s, at least one per 10 min",
          "[progress]") {
  SECTION("a fast run (30 s): one line per 10 s and the last") {
    PlainProgressRule rule;
    long lines = 0;
    for (long step = 1; step <= 100000; ++step)
      lines += rule.due(step, 100000, 30.0 * step / 100000, step == 100000);
    CHECK(lines == 3);  // at 10, 20 and 30 s (the last step)
  }
  SECTION("a run of 2 h: one line per 1 % (100 lines), none closer than 10 s") {
    PlainProgressRule rule;
    long lines = 0;
    double last = 0.0, closest = 1e9;
    for (long step = 1; step <= 200000; ++step) {
      const double wall = 7200.0 * step / 200000;
      if (rule.due(step, 200000, wall, step == 200000)) {
        ++lines;
        closest = std::min(closest, wall - last);
        last = wall;
      }
    }
    CHECK(lines == 100);
    CHECK(closest >= PlainProgressRule::min_interval);
  }
  SECTION("a run of 50 h: 1 % lines and a heartbeat every 10 min, at most 101 + wall/600") {
    PlainProgressRule rule;
    long lines = 0;
    double last = 0.0, widest = 0.0;
    const long total = 1000000;
    const double seconds = 50 * 3600.0;
    for (long step = 1; step <= total; ++step) {
      const double wall = seconds * step / total;
      if (rule.due(step, total, wall, step == total)) {
        ++lines;
        widest = std::max(widest, wall - last);
        last = wall;
      }
    }
    CHECK(widest <= PlainProgressRule::heartbeat + 1.0);
    CHECK(lines >= static_cast<long>(seconds / PlainProgressRule::heartbeat));
    CHECK(lines <= 101 + static_cast<long>(seconds / PlainProgressRule::heartbeat));
  }
}

TEST_CASE("progress in a log has no carriage return, on a terminal it rewrites one line",
          "[progress]") {
  const std::string log = drive(false, 200000, 3600.0);
  CHECK(count(log, '\r') == 0);
  CHECK(count(log, '\n') == 100);
  // Every line holds step, % done, time, dt, energy error, rate, wall time and ETA.
  const std::regex line(
      R"(step \d+/200000 \(\d+\.\d %\)  t = \S+ s  dt = 1e-06 s  energy error 1\.00e-05  )"
      R"(\S+ steps/s  wall \d+:\d\d:\d\d  ETA \d+:\d\d:\d\d)");
  std::size_t at = 0;
  for (std::size_t end; (end = log.find('\n', at)) != std::string::npos; at = end + 1) {
    INFO(log.substr(at, end - at));
    CHECK(std::regex_match(log.substr(at, end - at), line));
  }
  CHECK(log.find("step 200000/200000 (100.0 %)") != std::string::npos);
  CHECK(log.find("wall 1:00:00  ETA 0:00:00") != std::string::npos);

  const std::string tty = drive(true, 200000, 3600.0);
  CHECK(count(tty, '\r') > 100);
  CHECK(count(tty, '\n') == 1);  // the line is ended once, at the last step
}

TEST_CASE("fdem run into a file or a pipe writes plain progress lines", "[progress][cli]") {
  TempDir dir;
  write_text(dir / "scene.yaml", R"(name: falling-box
time: {end: 0.05}
gravity: [0, 0, -9.81]
materials:
  rubber: {density: 1000, elastic: {young: 1.0e6, poisson: 0.3}}
bodies:
  - {name: box, mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2]}}, material: rubber}
output: {every: 0.025}
)");
  const auto outcome = fdem_test::run_fdem(dir, "run scene.yaml -o file_run");
  REQUIRE(outcome.exit_code == 0);
  CHECK(count(outcome.err, '\r') == 0);
  const std::regex progress(R"((^|\n)step \d+/\d+ \(100\.0 %\)[^\n]*ETA 0:00:00\n)");
  CHECK(std::regex_search(outcome.err, progress));
  const auto lines = std::count(outcome.err.begin(), outcome.err.end(), '\n');
  CHECK(lines < 30);  // progress (1 line for a run this short), the stage table, the closing line

  const std::string piped = dir / "piped.txt";
  const std::string command = "cd '" + dir.path().string() + "' && '" + FDEM_BINARY +
                              "' run scene.yaml -o pipe_run 2>&1 | cat > '" + piped + "'";
  REQUIRE(std::system(command.c_str()) == 0);
  const std::string text = read_text(piped);
  CHECK(count(text, '\r') == 0);
  CHECK(std::regex_search(text, progress));
}
