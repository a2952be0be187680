// A wall's true raw value from the thesis's hyperboloid (Eq. 4.2): its vertex,
// the minimum of the r^2 surface fitted to the wall. With stock optics the
// wall barely billows, so a slight raw ramp across it must not send the vertex
// far off the wall, where the surface would extrapolate far below every pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "stages/planar_cleanup.h"

namespace speckle {
namespace {

CameraIntrinsics NominalDepthCamera() {
  CameraIntrinsics depth;
  depth.image_size = {640, 480};
  depth.camera_matrix = cv::Matx33d(580, 0, 320, 0, 580, 240, 0, 0, 1);
  return depth;
}

// r^2 = r0^2 + 2 r0 ramp x + billow (x^2 + y^2), with the sensor's noise,
// rounded to raw units.
cv::Mat Wall(double r0, double ramp, double billow) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0, 0.5);
  cv::Mat raw(480, 640, CV_16U);
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const double x = (u - 320) / 580.0, y = (v - 240) / 580.0;
      raw.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(
          std::lround(std::sqrt(r0 * r0 + 2 * r0 * ramp * x + billow * (x * x + y * y)) + noise(rng)));
    }
  }
  return raw;
}

TEST(PlanarCleanup, AWallThatBarelyBillowsKeepsItsVertexOnTheWall) {
  // A ramp of 8 raw per unit x (9 raw across the image) and a billow of
  // 1000 raw^2 (0.2 raw at the corners): the surface's own vertex lies 11
  // image half-widths to the left, 24 raw below the wall's centre; on the
  // wall, the lowest point is its left edge (x = -0.54), 4.1 raw below it.
  const auto snap = RunPlanarCleanup({}, NominalDepthCamera(), Wall(741, 8, 1000), 0);
  ASSERT_TRUE(std::holds_alternative<PlanarSnapshot>(snap));
  const PlanarSnapshot& s = std::get<PlanarSnapshot>(snap);
  EXPECT_NEAR(s.true_raw_hyperboloid, 736.9, 1.0);
  EXPECT_GE(s.true_raw_hyperboloid, s.true_raw_image_min - 0.5) << "the vertex is on the wall";
}

TEST(PlanarCleanup, ABillowingWallSquareToTheSensorHasItsVertexAtTheCentre) {
  // Wide-angle billowing (thesis Fig. 4.2): raw grows towards the edges.
  const auto snap = RunPlanarCleanup({}, NominalDepthCamera(), Wall(741, 0, 60000), 0);
  ASSERT_TRUE(std::holds_alternative<PlanarSnapshot>(snap));
  EXPECT_NEAR(std::get<PlanarSnapshot>(snap).true_raw_hyperboloid, 741, 0.5);
}

}  // namespace
}  // namespace speckle
