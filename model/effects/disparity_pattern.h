#pragma once
// A fixed per-pixel raw pattern whose size decays with disparity (Herrera et
// al., TPAMI 2012): offset = P(u, v) exp(-decay (raw - 600)), P a smooth
// field (bicubic B-spline, 7 x 5 control values).
#include "model/bspline_field.h"
#include "model/effect.h"

namespace speckle::model {
struct DisparityPattern {
  using Field = BSplineField<7, 5>;
  static constexpr const char* kName = "disparity_pattern";
  static constexpr const char* kDoc = "fixed per-pixel raw pattern whose size decays with disparity (Herrera 2012)";
  static std::vector<EffectParameter> Parameters() {
    std::vector<EffectParameter> p{{"decay", "1/raw", 0.003, 0, 0.05}};
    for (int k = 0; k < Field::kParameters; ++k) p.push_back({"pattern_" + std::to_string(k), "raw", 0, -50, 50, 5});
    return p;
  }
  static std::vector<std::string> CovariatesRead() { return {"raw", "u", "v"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    using std::exp;
    return Field::Evaluate(p + 1, c.u, c.v) * exp(-p[0] * (c.raw - 600));
  }
};
SPECKLE_MODEL_EFFECT(DisparityPattern)
}  // namespace speckle::model
