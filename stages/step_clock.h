#pragma once
// Wall-clock time of the steps a user waits for after the graph (fits, their
// camera refits and folds, diagnosis candidates, wall hold-outs), and a
// one-line progress display for the long ones. Steps that run side by side
// each keep their own wall time, so their sum exceeds the step around them.
#include <chrono>
#include <string>

namespace speckle {

class StepClock {
 public:
  StepClock() : start_(std::chrono::steady_clock::now()) {}
  double Seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

// (recorder/progress.h draws a frame counter; this one counts parallel parts.)
// "what k of n (name)" on stderr, overwriting itself, when stderr is a
// terminal and the step has run longer than kAfterSeconds (a short step stays
// quiet); nothing otherwise. Thread-safe: parallel parts report as they end.
class StepProgress {
 public:
  static constexpr double kAfterSeconds = 2.0;
  StepProgress(std::string what, int total);
  ~StepProgress();  // ends the line if anything was shown
  StepProgress(const StepProgress&) = delete;
  StepProgress& operator=(const StepProgress&) = delete;
  void Done(const std::string& name = "");  // one more of `total` has ended

 private:
  std::string what_;
  int total_ = 0, done_ = 0;
  bool shown_ = false;
  StepClock clock_;
};

}  // namespace speckle
