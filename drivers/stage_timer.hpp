// Adds the wall time of a scope to a stage's clock (summary.json "stages").
#pragma once

#include <chrono>
#include <string>

namespace fdem {

struct StageClock {
  std::string name;
  double seconds = 0.0;
  long calls = 0;
};

class Timed {
 public:
  explicit Timed(StageClock& clock) : clock_(clock), start_(std::chrono::steady_clock::now()) {}
  ~Timed() {
    clock_.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    ++clock_.calls;
  }
  Timed(const Timed&) = delete;
  Timed& operator=(const Timed&) = delete;

 private:
  StageClock& clock_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace fdem
