// Wall and CPU time of the solver's phases (JointViewResult::phases).
#pragma once

#include <ctime>
#include <vector>

#include "u4d/joint/joint_view.h"
#include "u4d/util/timer.h"

namespace u4d {

class PhaseClock {
 public:
  explicit PhaseClock(std::vector<JointViewResult::Phase>* phases) : phases_(phases) {}
  // Records the time since the last End or Restart as phase `name`, and restarts.
  void End(const char* name) {
    const std::clock_t now = std::clock();
    phases_->push_back(
        {name, timer_.Seconds(), static_cast<double>(now - cpu_start_) / CLOCKS_PER_SEC});
    timer_ = Timer();
    cpu_start_ = now;
  }
  void Restart() {
    timer_ = Timer();
    cpu_start_ = std::clock();
  }

 private:
  std::vector<JointViewResult::Phase>* phases_;
  Timer timer_;
  std::clock_t cpu_start_ = std::clock();
};

}  // namespace u4d
