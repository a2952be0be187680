#pragma once
// A fixed per-pixel distortion of raw values whose size decays with
// disparity, as Herrera et al. (TPAMI 2012) model the Kinect:
//   delta_r(u, v) = amplitude * P(u, v) * exp(-decay * (r - 600)),
// P a smooth random field of unit RMS that grows towards the image corners.
// Near objects (small raw values) show the pattern strongly, far ones weakly.
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "simulator/sim_effect.h"

namespace speckle::sim {

class DisparityPattern : public SimEffect {
 public:
  static constexpr const char* kName = "disparity_pattern";
  static constexpr const char* kDoc =
      "fixed per-pixel raw-value pattern whose size decays with disparity (Herrera 2012)";

  DisparityPattern(JsonFields& f, const SceneContext& c)
      : amplitude_(f.RequiredInRange("amplitude_raw", 0, 50)),
        decay_(f.RequiredInRange("decay_per_raw", 0, 0.05)),
        cells_(static_cast<int>(f.OptionalInRange("cells", 8, 2, 64))) {
    std::mt19937_64 rng(c.seed ^ 0x9e3779b97f4a7c15ULL);
    std::normal_distribution<float> normal(0, 1);
    cv::Mat coarse(cells_ * 3 / 4 + 1, cells_ + 1, CV_32F);
    for (int i = 0; i < static_cast<int>(coarse.total()); ++i) coarse.at<float>(i) = normal(rng);
    cv::resize(coarse, pattern_, cv::Size(c.width, c.height), 0, 0, cv::INTER_CUBIC);
    for (int v = 0; v < c.height; ++v) {
      for (int u = 0; u < c.width; ++u) {
        const double ru = (u - c.width / 2.0) / (c.width / 2.0), rv = (v - c.height / 2.0) / (c.height / 2.0);
        pattern_.at<float>(v, u) *= static_cast<float>(1 + ru * ru + rv * rv);
      }
    }
    cv::Scalar mean, stddev;
    cv::meanStdDev(pattern_, mean, stddev);
    pattern_ = (pattern_ - mean[0]) / stddev[0];
  }

  nlohmann::json Parameters() const override {
    return {{"amplitude_raw", amplitude_}, {"decay_per_raw", decay_}, {"cells", cells_}};
  }
  double RawOffset(const DepthSample& s) const override {
    return amplitude_ * pattern_.at<float>(s.v, s.u) * std::exp(-decay_ * (s.raw - 600));
  }

 private:
  double amplitude_, decay_;
  int cells_;
  cv::Mat pattern_;
};
SPECKLE_SIM_EFFECT(DisparityPattern)

}  // namespace speckle::sim
