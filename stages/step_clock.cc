#include "stages/step_clock.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>

namespace speckle {
namespace {
std::mutex& LineMutex() {
  static std::mutex m;  // one progress line on the terminal at a time
  return m;
}
bool Terminal() {
  static const bool terminal = isatty(STDERR_FILENO) == 1;
  return terminal;
}
}  // namespace

StepProgress::StepProgress(std::string what, int total) : what_(std::move(what)), total_(total) {}

StepProgress::~StepProgress() {
  if (!shown_) return;
  const std::lock_guard<std::mutex> lock(LineMutex());
  std::fputs("\n", stderr);
  std::fflush(stderr);
}

void StepProgress::Done(const std::string& name) {
  if (!Terminal()) return;
  const std::lock_guard<std::mutex> lock(LineMutex());
  ++done_;
  const double seconds = clock_.Seconds();
  if (seconds < kAfterSeconds) return;
  shown_ = true;
  // \r and clear to the end of the line: the next report overwrites this one.
  std::fputs(fmt::format("\r\033[K{} {} of {}{} ({:.0f} s)", what_, done_, total_, name.empty() ? "" : " done: " + name,
                         seconds)
                 .c_str(),
             stderr);
  std::fflush(stderr);
}

}  // namespace speckle
