#include "recorder/sources/pnm.h"

#include <cctype>
#include <fstream>
#include <iterator>
#include <string>

#include "schemas/errors.h"

namespace speckle {
namespace {

struct PnmHeader {
  std::string magic;
  int width = 0, height = 0, maxval = 0;
  std::size_t data_offset = 0;
};

PnmHeader ParseHeader(const std::string& bytes, const std::string& where) {
  PnmHeader h;
  std::size_t pos = 0;
  auto skip_space = [&] {
    while (pos < bytes.size()) {
      if (bytes[pos] == '#') {
        while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
      } else if (std::isspace(static_cast<unsigned char>(bytes[pos]))) {
        ++pos;
      } else {
        break;
      }
    }
  };
  auto read_int = [&](const char* field) {
    skip_space();
    const std::size_t start = pos;
    while (pos < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[pos]))) ++pos;
    if (start == pos || pos - start > 7) throw InputError(where + ": malformed PNM header (bad " + field + ")");
    return std::stoi(bytes.substr(start, pos - start));
  };
  if (bytes.size() < 2) throw InputError(where + ": empty or truncated file (expected a PNM header)");
  h.magic = bytes.substr(0, 2);
  pos = 2;
  h.width = read_int("width");
  h.height = read_int("height");
  h.maxval = read_int("maxval");
  if (pos >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[pos]))) {
    throw InputError(where + ": malformed PNM header (expected one whitespace after maxval)");
  }
  h.data_offset = pos + 1;
  return h;
}

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open");
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string Describe(const std::set<int>& values) {
  std::string s;
  for (int v : values) s += (s.empty() ? "" : " or ") + std::to_string(v);
  return s;
}

void Check(const PnmHeader& h, const std::string& magic, const PnmExpectation& expected, std::size_t bytes_per_pixel,
           std::size_t file_size, const std::string& where) {
  if (h.magic != magic)
    throw InputError(where + ": expected a binary " + magic + " file, found magic \"" + h.magic + "\"");
  if (h.width != expected.size.width || h.height != expected.size.height) {
    throw InputError(where + ": frame is " + std::to_string(h.width) + "x" + std::to_string(h.height) + ", expected " +
                     std::to_string(expected.size.width) + "x" + std::to_string(expected.size.height));
  }
  if (!expected.maxvals.count(h.maxval)) {
    throw InputError(where + ": maxval " + std::to_string(h.maxval) + ", expected " + Describe(expected.maxvals));
  }
  const std::size_t need = h.data_offset + std::size_t(h.width) * h.height * bytes_per_pixel;
  if (file_size < need) {
    throw InputError(where + ": truncated: " + std::to_string(file_size) + " bytes, expected " + std::to_string(need));
  }
  if (file_size > need) {
    throw InputError(where + ": " + std::to_string(file_size - need) + " unexpected bytes after the image data");
  }
}

}  // namespace

cv::Mat ReadPgm16(const std::filesystem::path& path, ByteOrder order, const PnmExpectation& expected) {
  const std::string bytes = Slurp(path);
  const PnmHeader h = ParseHeader(bytes, path.string());
  Check(h, "P5", expected, 2, bytes.size(), path.string());
  cv::Mat image(h.height, h.width, CV_16UC1);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + h.data_offset);
  auto* out = image.ptr<std::uint16_t>();
  const std::size_t n = image.total();
  const int hi = order == ByteOrder::kBigEndian ? 0 : 1;
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = static_cast<std::uint16_t>((data[2 * i + hi] << 8) | data[2 * i + 1 - hi]);
    // A value above maxval is not what the header promised (and not a raw
    // 11-bit reading): refuse it instead of storing it.
    if (out[i] > h.maxval) {
      throw InputError(path.string() + ": pixel (" + std::to_string(i % h.width) + ", " + std::to_string(i / h.width) +
                       ") holds " + std::to_string(out[i]) + ", above the header's maxval " + std::to_string(h.maxval));
    }
  }
  return image;
}

cv::Mat ReadPpm8(const std::filesystem::path& path, const PnmExpectation& expected) {
  const std::string bytes = Slurp(path);
  const PnmHeader h = ParseHeader(bytes, path.string());
  Check(h, "P6", expected, 3, bytes.size(), path.string());
  cv::Mat image(h.height, h.width, CV_8UC3);
  std::copy(bytes.begin() + static_cast<std::ptrdiff_t>(h.data_offset), bytes.end(), image.data);
  return image;
}

}  // namespace speckle
