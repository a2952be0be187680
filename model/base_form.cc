#include "model/base_form.h"

#include "schemas/errors.h"

namespace speckle::model {

const std::vector<BaseFormInfo>& BaseForms() {
  // Initial values: the thesis's stock-optics fits, which converge for any
  // Kinect-class sensor.
  static const std::vector<BaseFormInfo> forms = {
      {BaseForm::kReciprocal, "reciprocal", {"a", "b"}, {"1/(m raw)", "1/m"}, {-0.0027681, 3.0163}},
      {BaseForm::kTangent, "tangent", {"c", "k", "b"}, {"m", "raw", "1"}, {0.15257, 2431.3, 1.1200}},
      {BaseForm::kDisparity, "disparity", {"bf8", "doff"}, {"m raw", "raw"}, {348.0, 1090.0}},
      {BaseForm::kLinearMm, "linear_mm", {"a", "b"}, {"m/mm", "m"}, {0.001, 0.0}},
  };
  return forms;
}

const BaseFormInfo& Info(BaseForm form) {
  for (const auto& f : BaseForms())
    if (f.form == form) return f;
  throw std::logic_error("unknown base form");
}

BaseForm BaseFormFromName(const std::string& name) {
  std::string known;
  for (const auto& f : BaseForms()) {
    if (name == f.name) return f.form;
    known += (known.empty() ? "" : ", ") + std::string(f.name);
  }
  throw InputError("unknown base form \"" + name + "\" (expected one of: " + known + ")");
}

}  // namespace speckle::model
