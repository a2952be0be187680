#pragma once
// Ctrl-C (SIGINT) and SIGTERM during recording set StopRequested(), so sources
// end their stream cleanly instead of the process dying mid-write.
#include <csignal>

#include "recorder/frame_source.h"

namespace speckle {

// Installs the stop handlers for its lifetime and restores the previous ones.
class StopSignalScope {
 public:
  StopSignalScope() {
    StopRequested().store(false);
    previous_int_ = std::signal(SIGINT, OnStopSignal);
    previous_term_ = std::signal(SIGTERM, OnStopSignal);
  }
  ~StopSignalScope() {
    std::signal(SIGINT, previous_int_);
    std::signal(SIGTERM, previous_term_);
  }
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;

 private:
  static void OnStopSignal(int) { StopRequested().store(true); }
  void (*previous_int_)(int);
  void (*previous_term_)(int);
};

}  // namespace speckle
