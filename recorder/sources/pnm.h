#pragma once
// Binary PGM/PPM frames as Kinect tools write them. The byte order of 16-bit
// PGMs is a parameter because libfreenect's `record` writes host order
// (little-endian) against the PGM spec, while calibration toolboxes write
// the standard big-endian.
#include <filesystem>
#include <opencv2/core.hpp>
#include <set>

namespace speckle {

enum class ByteOrder { kBigEndian, kLittleEndian };

struct PnmExpectation {
  cv::Size size{640, 480};
  std::set<int> maxvals;  // allowed maxval values
};

// A 16-bit P5 image as CV_16UC1. Throws InputError naming the file.
cv::Mat ReadPgm16(const std::filesystem::path& path, ByteOrder order, const PnmExpectation& expected);
// An 8-bit P6 image as CV_8UC3 in RGB order.
cv::Mat ReadPpm8(const std::filesystem::path& path, const PnmExpectation& expected);

}  // namespace speckle
