#pragma once
// Which depth pixel values are readings, from the recording's depth units:
// the one rule every stage, the apply library and the recorder share.
//
//   raw_11bit  libfreenect's raw disparity: 2047 (and above) = no reading;
//   millimetre the OpenNI driver's depth (ROS openni/freenect 16UC1 depth,
//              TUM RGB-D after /5): 0 = no reading.
//
// 0 is never a reading in either unit (no Kinect reports raw 0: it would be
// nearer than the projector).
//
// Stages keep their tolerances in raw units, where the sensor's noise and
// quantization are (one disparity step of 1/8 px). A millimetre value is a
// raw value through the driver's conversion, so its steps grow with depth
// squared: UnitsPerRawStep converts a raw-unit tolerance to the recording's
// units at a given value, and StepValue maps a value to a scale on which a
// fixed raw tolerance applies everywhere (the nominal Kinect's disparity).
#include <cstdint>

#include "schemas/session_manifest.h"

namespace speckle {

class DepthReading {
 public:
  DepthReading() = default;  // raw 11-bit, so options built with {} read as before
  explicit DepthReading(DepthUnits units) : units_(units) {}

  DepthUnits units() const { return units_; }

  // The value a recording writes where the sensor has no reading.
  std::uint16_t NoReadingValue() const { return units_ == DepthUnits::kRaw11Bit ? 2047 : 0; }

  bool IsReading(std::uint16_t value) const { return value >= 1 && (units_ != DepthUnits::kRaw11Bit || value < 2047); }

  // How many of the recording's units one raw step spans near `value`.
  double UnitsPerRawStep(double value) const {
    if (units_ == DepthUnits::kRaw11Bit) return 1;
    // z = 1 / (a r + b) -> dz/dr = -a z^2; in millimetres a z_mm^2 / 1000.
    return kNominalA * value * value / 1000;
  }

  // `value` on a raw-like scale (nominal disparity steps) for tolerances in
  // raw units; the identity for raw values.
  double StepValue(double value) const {
    if (units_ == DepthUnits::kRaw11Bit) return value;
    return -1000 / (kNominalA * value);  // 1/z over a: raw up to a constant
  }

 private:
  // The stock Kinect's reciprocal slope (1/m per raw unit, Burrus; thesis
  // Table 3.1): only a scale for tolerances, never a calibration.
  static constexpr double kNominalA = 0.0027681;
  DepthUnits units_ = DepthUnits::kRaw11Bit;
};

}  // namespace speckle
