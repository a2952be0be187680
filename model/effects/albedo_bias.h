#pragma once
// IR reflectivity: dark squares return less of the speckle pattern and the
// correlation reads them biased: offset = dark_bias * (1 - albedo).
#include "model/effect.h"

namespace speckle::model {
struct AlbedoBias {
  static constexpr const char* kName = "albedo_bias";
  static constexpr const char* kDoc = "dark (low IR albedo) surfaces read biased raw values";
  static std::vector<EffectParameter> Parameters() { return {{"dark_bias", "raw", 0, -30, 30}}; }
  static std::vector<std::string> CovariatesRead() { return {"albedo"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    return p[0] * (1 - c.albedo);
  }
};
SPECKLE_MODEL_EFFECT(AlbedoBias)
}  // namespace speckle::model
