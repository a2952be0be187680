#pragma once
// "stage: done / total" on one terminal line, redrawn at most 10 times a
// second; silent when stderr is not a terminal.
#include <chrono>
#include <cstdint>
#include <string>

namespace speckle {

class Progress {
 public:
  Progress(std::string stage, std::int64_t total);  // total < 0: unknown
  ~Progress();
  void Update(std::int64_t done);
  void Finish();

 private:
  void Draw(std::int64_t done);
  std::string stage_;
  std::int64_t total_;
  std::int64_t done_ = 0;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace speckle
