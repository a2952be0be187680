#pragma once
// Colour frames from JPEG or PNG files, checked before and after decoding:
// the size the header claims is bounded before any pixel is decoded (a 33 KB
// JPEG can claim 16000 x 16000), and a JPEG cut short (no end-of-image
// marker; libjpeg would fill the missing rows with grey and only warn) fails
// the frame instead of being stored.
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace speckle {

// The largest colour frame side accepted (Kinect colour is at most 1280 x 1024).
inline constexpr int kMaxColourSide = 4096;

// The width and height a JPEG (SOFn) or PNG (IHDR) header claims; nothing when
// the bytes hold neither.
std::optional<cv::Size> ClaimedImageSize(const std::string& bytes);

// A JPEG or PNG file's bytes once its header's size is bounded, before any
// pixel is decoded; InputError names the file and `expected` otherwise.
std::string ReadImageBytesWithin(const std::filesystem::path& path, int max_side, const std::string& expected);

// Reads a colour JPEG or PNG as RGB; InputError names the file when it is
// unreadable, claims an absurd size or is truncated.
cv::Mat ReadColourImage(const std::filesystem::path& path);

}  // namespace speckle
