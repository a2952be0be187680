#pragma once
// Options check themselves, as Ceres's Solver::Options::IsValid does: each
// options struct's IsValid(std::string* why) states its rules through an
// OptionCheck, which keeps the first one broken, named by its field:
//   return OptionCheck(why).AtLeast(folds, 0, "folds").Positive(huber_raw, "huber_raw").valid();
// A struct holding another's options checks them as Part("segmentation", segmentation),
// so a broken rule names its whole path ("planar.segmentation.stride").
#include <cmath>
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
  // Finite and above 0.
  OptionCheck& Positive(double value, const char* field) {
    return Require(std::isfinite(value) && value > 0, field, "finite and > 0");
  }
  // Finite and at least `least`.
  OptionCheck& AtLeast(double value, double least, const char* field) {
    return Require(std::isfinite(value) && value >= least, field, "finite and >= " + Number(least));
  }
  // A share: from 0 to 1.
  OptionCheck& Share(double value, const char* field) {
    return Require(value >= 0 && value <= 1, field, "a share from 0 to 1");
  }
  template <typename Options>
  OptionCheck& Part(const char* name, const Options& part) {
    std::string part_why;
    if (valid_ && !part.IsValid(&part_why)) {
      valid_ = false;
      if (why_) *why_ = std::string(name) + "." + part_why;
    }
    return *this;
  }
  bool valid() const { return valid_; }

 private:
  static std::string Number(double v) {
    std::string s = std::to_string(v);
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
  }
  std::string* why_;
  bool valid_ = true;
};

}  // namespace speckle
