#pragma once
// The base forms relating a raw value r to depth z (metres). Each is
// templated on the scalar for Ceres autodiff and has a closed-form inverse,
// because fits put their residuals in raw units, where the sensor's noise is.
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace speckle::model {

enum class BaseForm {
  kReciprocal,  // z = 1 / (a r + b)              Burrus; the thesis's stock fit
  kTangent,     // z = c tan(r / k + b)           Magnenat
  kDisparity,   // z = bf8 / (doff - r)           ROS kinect_calibration (bf8 = 8 baseline f)
  kLinearMm,    // z = a r + b, r in driver mm    OpenNI (thesis App. C)
};

// The most parameters a base form has (the tangent form's c, k, b).
inline constexpr int kMaxBaseParameters = 3;

struct BaseFormInfo {
  BaseForm form;
  const char* name;
  std::vector<std::string> parameters;
  std::vector<std::string> units;
  std::vector<double> initial;
};

const std::vector<BaseFormInfo>& BaseForms();
const BaseFormInfo& Info(BaseForm form);
BaseForm BaseFormFromName(const std::string& name);  // throws InputError

// Depth from raw value.
template <typename T>
T DepthFromRaw(BaseForm form, const T* p, const T& r) {
  using std::atan;
  using std::tan;
  switch (form) {
    case BaseForm::kReciprocal:
      return T(1) / (p[0] * r + p[1]);
    case BaseForm::kTangent:
      return p[0] * tan(r / p[1] + p[2]);
    case BaseForm::kDisparity:
      return p[0] / (p[1] - r);
    case BaseForm::kLinearMm:
      return p[0] * r + p[1];
  }
  return T(0);
}

// Raw value from depth: the inverse of DepthFromRaw.
template <typename T>
T RawFromDepth(BaseForm form, const T* p, const T& z) {
  using std::atan;
  switch (form) {
    case BaseForm::kReciprocal:
      return (T(1) / z - p[1]) / p[0];
    case BaseForm::kTangent:
      return p[1] * (atan(z / p[0]) - p[2]);
    case BaseForm::kDisparity:
      return p[1] - p[0] / z;
    case BaseForm::kLinearMm:
      return (z - p[1]) / p[0];
  }
  return T(0);
}

}  // namespace speckle::model
