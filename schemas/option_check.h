#pragma once
// Options check themselves, as Ceres's Solver::Options::IsValid does: each
// options struct's IsValid(std::string* why) states its rules through an
// OptionCheck, which keeps the first one broken, named by its field:
//   return OptionCheck(why).Require(folds >= 0, "folds", ">= 0, found " + ...).valid();
#include <string>

namespace speckle {

class OptionCheck {
 public:
  explicit OptionCheck(std::string* why) : why_(why) {}
  OptionCheck& Require(bool holds, const char* field, const std::string& rule) {
    if (!holds && valid_) {
      valid_ = false;
      if (why_) *why_ = std::string(field) + " must be " + rule;
    }
    return *this;
  }
  bool valid() const { return valid_; }

 private:
  std::string* why_;
  bool valid_ = true;
};

}  // namespace speckle
