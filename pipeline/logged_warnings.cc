#include "pipeline/logged_warnings.h"

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
    return kept_;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (msg.level < spdlog::level::warn) return;
    std::string text(msg.payload.data(), msg.payload.size());
    if (std::find(kept_.begin(), kept_.end(), text) == kept_.end()) kept_.push_back(std::move(text));
  }
  void flush_() override {}

 private:
  std::vector<std::string> kept_;  // guarded by base_sink's mutex_ while logging
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
