#include "pipeline/logged_warnings.h"

#include <fmt/format.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <mutex>

namespace speckle {
namespace {

class WarningSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::vector<std::string> Kept() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out = kept_;
    if (more_ > 0) out.push_back(fmt::format("... and {} more warnings (the run's log has them)", more_));
    return out;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (msg.level < spdlog::level::warn) return;
    std::string text(msg.payload.data(), msg.payload.size());
    if (std::find(kept_.begin(), kept_.end(), text) != kept_.end()) return;
    if (kept_.size() < kMaxKept)
      kept_.push_back(std::move(text));
    else
      ++more_;
  }
  void flush_() override {}

 private:
  // A frame-by-frame warning repeated over thousands of frames would fill
  // report.json and the page: the first kMaxKept are kept, the rest counted.
  static constexpr std::size_t kMaxKept = 50;
  std::vector<std::string> kept_;  // guarded by base_sink's mutex_ while logging
  std::size_t more_ = 0;
};

std::shared_ptr<WarningSink>& Sink() {
  static std::shared_ptr<WarningSink> sink;
  return sink;
}

}  // namespace

void KeepLoggedWarnings() {
  if (Sink()) return;
  Sink() = std::make_shared<WarningSink>();
  spdlog::default_logger()->sinks().push_back(Sink());
}

std::vector<std::string> LoggedWarnings() { return Sink() ? Sink()->Kept() : std::vector<std::string>{}; }

}  // namespace speckle
