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

}  // namespace u4d
