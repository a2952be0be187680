#include "recorder/progress.h"

#include <unistd.h>

#include <cstdio>

namespace speckle {

Progress::Progress(std::string stage, std::int64_t total)
    : stage_(std::move(stage)), total_(total), enabled_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() { Finish(); }

void Progress::Update(std::int64_t done) {
  done_ = done;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  Draw(done);
}

void Progress::Draw(std::int64_t done) {
  if (total_ >= 0) {
    std::fprintf(stderr, "\r%s: %lld / %lld frames", stage_.c_str(), static_cast<long long>(done),
                 static_cast<long long>(total_));
  } else {
    std::fprintf(stderr, "\r%s: %lld frames (Ctrl-C stops)", stage_.c_str(), static_cast<long long>(done));
  }
  std::fflush(stderr);
}

void Progress::Finish() {
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  Draw(done_);
  std::fputc('\n', stderr);
}

}  // namespace speckle
