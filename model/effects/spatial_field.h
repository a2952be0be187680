#pragma once
// A smooth spatial offset and scale over the image, for structure no
// physical effect names: offset = O(u, v) + S(u, v) (raw - 800) / 100, O and
// S bicubic B-splines with 5 x 4 control values each.
#include "model/bspline_field.h"
#include "model/effect.h"

namespace speckle::model {
struct SpatialField {
  using Field = BSplineField<5, 4>;
  static constexpr const char* kName = "spatial_field";
  static constexpr const char* kDoc = "smooth spatial raw offset and scale over the image (bicubic B-splines)";
  static std::vector<EffectParameter> Parameters() {
    std::vector<EffectParameter> p;
    for (int k = 0; k < Field::kParameters; ++k) p.push_back({"offset_" + std::to_string(k), "raw", 0, -50, 50, 5});
    for (int k = 0; k < Field::kParameters; ++k)
      p.push_back({"scale_" + std::to_string(k), "raw/100raw", 0, -50, 50, 5});
    return p;
  }
  static std::vector<std::string> CovariatesRead() { return {"raw", "u", "v"}; }
  static double RawOffsetAndGradient(const double* p, const Covariates& c, double* gradient) {
    const double lever = (c.raw - 800) / 100;
    const double offset = Field::Evaluate(p, c.u, c.v, gradient);
    const double scale = Field::Evaluate(p + Field::kParameters, c.u, c.v, gradient + Field::kParameters);
    for (int k = Field::kParameters; k < 2 * Field::kParameters; ++k) gradient[k] *= lever;
    return offset + scale * lever;
  }
  static double RawOffset(const double* p, const Covariates& c) {
    return Field::Evaluate(p, c.u, c.v) + Field::Evaluate(p + Field::kParameters, c.u, c.v) * ((c.raw - 800) / 100);
  }
};
SPECKLE_MODEL_EFFECT(SpatialField)
}  // namespace speckle::model
