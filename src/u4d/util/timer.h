// Wall-clock timing and peak memory, for stage summaries and benchmarks.
#pragma once

#include <chrono>
#include <cstdint>

namespace u4d {

class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  void Restart() { start_ = std::chrono::steady_clock::now(); }
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Peak resident set size of this process in bytes (from getrusage).
int64_t PeakRssBytes();

// Peak memory of one stage: ResetPeakRss() resets the kernel's high-water
// mark (Linux: writing 5 to /proc/self/clear_refs; false when that is not
// possible) and CurrentPeakRssBytes() reads it (VmHWM of /proc/self/status,
// else PeakRssBytes()), so the value after a stage is that stage's peak.
bool ResetPeakRss();
int64_t CurrentPeakRssBytes();

}  // namespace u4d
