#pragma once
// The Kinect v1 / PrimeSense family's depth geometry, which every sensor of
// it shares whatever its optics: what a measurement is judged against when
// it must not depend on the board's stated size.
namespace speckle::model {

// The raw value is the projector-to-IR disparity in 1/8 px of the sensor's
// 640-wide depth image (raw = c - 8 fx B / z), whatever size the frames are
// delivered at.
inline constexpr double kDisparityImageWidth = 640;
// The projector's baseline B: 7.5 cm on every Kinect v1 and PrimeSense
// (thesis: 7.7 cm stock, 8.0 cm wide; Burrus's constants 6.9 cm), and the
// band a sensor of the family is taken to lie in.
inline constexpr double kFamilyBaselineM = 0.075, kMinBaselineM = 0.063, kMaxBaselineM = 0.093;
// The baselines sensors of the family were measured to have, 6.9-8.0 cm, with
// 3 % either side: what a direct measurement of a length by the depth alone
// (stages/board_size_in_depth.h) is held to before it is called wrong.
inline constexpr double kMinMeasuredBaselineM = 0.067, kMaxMeasuredBaselineM = 0.085;

}  // namespace speckle::model
