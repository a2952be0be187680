#include "recorder/sources/colour_image.h"

#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "schemas/errors.h"

namespace speckle {
namespace {

int Byte(const std::string& b, std::size_t i) { return static_cast<unsigned char>(b[i]); }
int BigEndian16(const std::string& b, std::size_t i) { return Byte(b, i) << 8 | Byte(b, i + 1); }

bool IsJpeg(const std::string& b) { return b.size() >= 3 && Byte(b, 0) == 0xFF && Byte(b, 1) == 0xD8; }
bool IsPng(const std::string& b) { return b.size() >= 8 && b.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0; }

std::optional<cv::Size> JpegSize(const std::string& b) {
  std::size_t pos = 2;
  while (pos + 4 <= b.size()) {
    if (Byte(b, pos) != 0xFF) return std::nullopt;
    const int marker = Byte(b, pos + 1);
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    const int length = BigEndian16(b, pos + 2);
    // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC).
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      if (pos + 9 > b.size()) return std::nullopt;
      return cv::Size(BigEndian16(b, pos + 7), BigEndian16(b, pos + 5));
    }
    if (length < 2) return std::nullopt;
    pos += 2 + static_cast<std::size_t>(length);
  }
  return std::nullopt;
}

// A complete JPEG ends with the EOI marker (FF D9), perhaps followed by padding.
bool JpegComplete(const std::string& b) {
  std::size_t end = b.size();
  while (end > 2 && (b[end - 1] == '\0' || b[end - 1] == '\n' || b[end - 1] == '\r')) --end;
  return end >= 4 && Byte(b, end - 2) == 0xFF && Byte(b, end - 1) == 0xD9;
}

}  // namespace

std::optional<cv::Size> ClaimedImageSize(const std::string& bytes) {
  if (IsJpeg(bytes)) return JpegSize(bytes);
  if (IsPng(bytes) && bytes.size() >= 24 && bytes.compare(12, 4, "IHDR") == 0) {
    const auto be32 = [&](std::size_t i) {
      return static_cast<long long>(BigEndian16(bytes, i)) << 16 | BigEndian16(bytes, i + 2);
    };
    const long long w = be32(16), h = be32(20);
    if (w > INT32_MAX || h > INT32_MAX) return cv::Size(INT32_MAX, INT32_MAX);
    return cv::Size(static_cast<int>(w), static_cast<int>(h));
  }
  return std::nullopt;
}

std::string ReadImageBytesWithin(const std::filesystem::path& path, int max_side, const std::string& expected) {
  const std::string where = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(where + ": cannot open");
  std::string bytes{std::istreambuf_iterator<char>(in), {}};
  const std::optional<cv::Size> claimed = ClaimedImageSize(bytes);
  if (!claimed) throw InputError(where + ": not a readable image (expected " + expected + ")");
  if (claimed->width <= 0 || claimed->height <= 0 || claimed->width > max_side || claimed->height > max_side) {
    throw InputError(where + ": the header claims " + std::to_string(claimed->width) + "x" +
                     std::to_string(claimed->height) + " pixels, expected " + expected + " of at most " +
                     std::to_string(max_side) + " on each side");
  }
  return bytes;
}

cv::Mat ReadColourImage(const std::filesystem::path& path) {
  const std::string where = path.string();
  const std::string bytes = ReadImageBytesWithin(path, kMaxColourSide, "a colour JPEG or PNG");
  const cv::Size claimed = *ClaimedImageSize(bytes);
  if (IsJpeg(bytes) && !JpegComplete(bytes))
    throw InputError(where + ": truncated JPEG (no end-of-image marker); the missing rows would be grey");
  const cv::Mat bgr = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
                                   cv::IMREAD_COLOR);
  if (bgr.empty()) throw InputError(where + ": not a readable image (expected a colour JPEG or PNG)");
  if (bgr.size() != claimed) throw InputError(where + ": decoded size differs from the header's");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace speckle
