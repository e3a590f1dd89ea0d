#include "u4d/util/progress.h"

#include <cstdio>

#include <unistd.h>

namespace u4d {

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)), total_(total), enabled_(enabled && ::isatty(STDERR_FILENO)) {}

Progress::~Progress() { Finish(); }

void Progress::Tick(int64_t n) {
  done_ += n;
  if (enabled_) Draw();
}

void Progress::Draw() {
  std::lock_guard<std::mutex> lock(mutex_);
  const int64_t done = done_.load();
  const int width = 30;
  const int filled = total_ > 0 ? static_cast<int>(width * done / total_) : width;
  std::fprintf(stderr, "\r%-16s [%-*s] %lld/%lld", label_.c_str(), width,
               std::string(filled, '#').c_str(), static_cast<long long>(done),
               static_cast<long long>(total_));
  std::fflush(stderr);
}

void Progress::Finish() {
  if (finished_) return;
  finished_ = true;
  if (enabled_) std::fprintf(stderr, "\n");
}

}  // namespace u4d
