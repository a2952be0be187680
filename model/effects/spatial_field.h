#pragma once
// A smooth spatial offset and scale over the image, for structure no
// physical effect names: offset = O(u, v) + S(u, v) (raw - 800) / 100, O and
// S each a plane over the image plus a bicubic B-spline of 5 x 4 control
// values. The splines carry weak priors (where no board ever was they would
// extrapolate wildly); the planes carry none, so a tilt across the whole
// image, which a pattern slightly rotated against its reference makes, costs
// nothing and is followed into corners few poses reach. (Hunt linear_offset,
// seeds 1-5: 4 of 5 end within 1.15x the floor, 2 of 5 without the planes;
// Herrera's set held out 1.168 raw, 1.194 without.) The plane terms come
// last: model specs naming the older ones read as planes of zero, while a
// calibration fitted without them is refused by its parameter count.
#include "model/bspline_field.h"
#include "model/effect.h"

namespace speckle::model {
struct SpatialField {
  using Field = BSplineField<5, 4>;
  static constexpr int kPlane = 2 * Field::kParameters;  // the first plane parameter
  static constexpr const char* kName = "spatial_field";
  static constexpr const char* kDoc =
      "smooth spatial raw offset and scale over the image (planes plus bicubic B-splines)";
  static std::vector<EffectParameter> Parameters() {
    std::vector<EffectParameter> p;
    for (int k = 0; k < Field::kParameters; ++k) p.push_back({"offset_" + std::to_string(k), "raw", 0, -50, 50, 5});
    for (int k = 0; k < Field::kParameters; ++k)
      p.push_back({"scale_" + std::to_string(k), "raw/100raw", 0, -50, 50, 5});
    // At the image's right (bottom) edge, against its centre.
    p.push_back({"offset_tilt_u", "raw", 0, -50, 50});
    p.push_back({"offset_tilt_v", "raw", 0, -50, 50});
    p.push_back({"scale_tilt_u", "raw/100raw", 0, -50, 50});
    p.push_back({"scale_tilt_v", "raw/100raw", 0, -50, 50});
    return p;
  }
  static std::vector<std::string> CovariatesRead() { return {"raw", "u", "v"}; }
  static double RawOffsetAndGradient(const double* p, const Covariates& c, double* gradient) {
    const double lever = (c.raw - 800) / 100;
    const double offset = Field::Evaluate(p, c.u, c.v, gradient);
    const double scale = Field::Evaluate(p + Field::kParameters, c.u, c.v, gradient + Field::kParameters);
    for (int k = Field::kParameters; k < kPlane; ++k) gradient[k] *= lever;
    const double tu = TiltU(c), tv = TiltV(c);
    gradient[kPlane] = tu, gradient[kPlane + 1] = tv;
    gradient[kPlane + 2] = tu * lever, gradient[kPlane + 3] = tv * lever;
    return offset + scale * lever + Plane(p + kPlane, c) + Plane(p + kPlane + 2, c) * lever;
  }
  static double RawOffset(const double* p, const Covariates& c) {
    const double lever = (c.raw - 800) / 100;
    return Field::Evaluate(p, c.u, c.v) + Plane(p + kPlane, c) +
           (Field::Evaluate(p + Field::kParameters, c.u, c.v) + Plane(p + kPlane + 2, c)) * lever;
  }

 private:
  static double TiltU(const Covariates& c) { return (c.u - Field::kWidth / 2) / (Field::kWidth / 2); }
  static double TiltV(const Covariates& c) { return (c.v - Field::kHeight / 2) / (Field::kHeight / 2); }
  static double Plane(const double* tilt, const Covariates& c) { return tilt[0] * TiltU(c) + tilt[1] * TiltV(c); }
};
SPECKLE_MODEL_EFFECT(SpatialField)
}  // namespace speckle::model
