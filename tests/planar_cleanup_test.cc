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

// A wide-angle camera (fx 373) looking at a tilted wall whose raw value is
// the plane r = c0 + c1 x + c2 y, billowed as the thesis's Eq. 4.2 has it:
// measured^2 = r^2 + bx x^2 + by y^2.
cv::Mat BillowedPlane(double c0, double c1, double c2, double bx, double by) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0, 0.6);
  cv::Mat raw(480, 640, CV_16U);
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const double x = (u - 320) / 373.0, y = (v - 240) / 373.0, r = c0 + c1 * x + c2 * y;
      raw.at<std::uint16_t>(v, u) =
          static_cast<std::uint16_t>(std::lround(std::sqrt(r * r + bx * x * x + by * y * y) + noise(rng)));
    }
  }
  return raw;
}

TEST(PlanarCleanup, ANearBillowingWallKeepsItsOwnPlane) {
  // 0.35 m from a wide-angle adapter, 1.9 degrees off square: billowing adds
  // up to 120 raw at the corners. Fitted on r with even terms, the plane came
  // out 3 raw shallower along x (18.8 instead of 21.7).
  CameraIntrinsics depth = NominalDepthCamera();
  depth.camera_matrix = cv::Matx33d(373, 0, 320, 0, 373, 240, 0, 0, 1);
  const auto snap = RunPlanarCleanup({}, depth, BillowedPlane(400.7, 21.7, 13.3, 120000, 50000), DepthReading{}, 0);
  ASSERT_TRUE(std::holds_alternative<PlanarSnapshot>(snap)) << std::get<Rejection>(snap).reason;
  const Eigen::Vector3d plane = std::get<PlanarSnapshot>(snap).raw_plane;
  EXPECT_NEAR(plane(0), 400.7, 0.1);
  EXPECT_NEAR(plane(1), 21.7, 0.3);
  EXPECT_NEAR(plane(2), 13.3, 0.3);
}

TEST(PlanarCleanup, AWallThatBarelyBillowsKeepsItsVertexOnTheWall) {
  // A ramp of 8 raw per unit x (9 raw across the image) and a billow of
  // 1000 raw^2 (0.2 raw at the corners): the surface's own vertex lies 11
  // image half-widths to the left, 24 raw below the wall's centre; on the
  // wall, the lowest point is its left edge (x = -0.54), 4.1 raw below it.
  const auto snap = RunPlanarCleanup({}, NominalDepthCamera(), Wall(741, 8, 1000), DepthReading{}, 0);
  ASSERT_TRUE(std::holds_alternative<PlanarSnapshot>(snap));
  const PlanarSnapshot& s = std::get<PlanarSnapshot>(snap);
  EXPECT_NEAR(s.true_raw_hyperboloid, 736.9, 1.0);
  EXPECT_GE(s.true_raw_hyperboloid, s.true_raw_image_min - 0.5) << "the vertex is on the wall";
}

TEST(PlanarCleanup, ABillowingWallSquareToTheSensorHasItsVertexAtTheCentre) {
  // Wide-angle billowing (thesis Fig. 4.2): raw grows towards the edges.
  const auto snap = RunPlanarCleanup({}, NominalDepthCamera(), Wall(741, 0, 60000), DepthReading{}, 0);
  ASSERT_TRUE(std::holds_alternative<PlanarSnapshot>(snap));
  EXPECT_NEAR(std::get<PlanarSnapshot>(snap).true_raw_hyperboloid, 741, 0.5);
}

}  // namespace
}  // namespace speckle
