// A progress bar on stderr for long work. Quiet when stderr is not a
// terminal (CI logs) or when disabled; thread-safe Tick().
#pragma once

#include <atomic>
#include <mutex>
#include <string>

namespace u4d {

class Progress {
 public:
  Progress(std::string label, int64_t total, bool enabled = true);
  ~Progress();
  void Tick(int64_t n = 1);
  void Finish();

 private:
  void Draw();
  std::string label_;
  int64_t total_;
  std::atomic<int64_t> done_{0};
  bool enabled_;
  bool finished_ = false;
  std::mutex mutex_;
};

}  // namespace u4d
