#include "recorder/sources/tum_source.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "recorder/sources/colour_image.h"
#include "recorder/sources/stamp_pairing.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

// TUM depth PNGs hold 5000 per metre: 5 per millimetre.
constexpr int kTumPerMillimetre = 5;

struct ListedFrame {
  std::int64_t stamp_ns = 0;
  fs::path file;
};

std::vector<ListedFrame> ReadList(const fs::path& dir, const std::string& name) {
  const fs::path list = dir / name;
  std::ifstream in(list);
  if (!in) throw InputError(list.string() + ": missing (a TUM RGB-D folder lists its frames in rgb.txt and depth.txt)");
  std::vector<ListedFrame> frames;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::istringstream fields(line);
    double stamp_s = 0;
    std::string file;
    if (!(fields >> stamp_s >> file) || !std::isfinite(stamp_s) || stamp_s < 0) {
      throw InputError(fmt::format("{}:{}: expected \"timestamp file\", found \"{}\"", list.string(), number, line));
    }
    const fs::path path = dir / file;
    if (!fs::is_regular_file(path))
      throw InputError(fmt::format("{}:{}: {} does not exist", list.string(), number, path.string()));
    frames.push_back({std::llround(stamp_s * 1e9), path});
  }
  return frames;
}

// An image file's bytes as OpenCV's decoders take them (not copied).
cv::Mat Bytes(const std::string& bytes) {
  return cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data()));
}

cv::Mat ReadTumDepth(const fs::path& path, std::optional<cv::Size> expected) {
  const std::string bytes = ReadImageBytesWithin(path, kMaxColourSide, "a 16-bit depth PNG");
  const cv::Mat png = cv::imdecode(Bytes(bytes), cv::IMREAD_UNCHANGED);
  if (png.empty()) throw InputError(path.string() + ": not a readable image (expected a 16-bit depth PNG)");
  if (png.type() != CV_16UC1) {
    throw InputError(path.string() + ": expected a 16-bit single-channel depth PNG (TUM: 5000 per metre), found " +
                     std::to_string(png.channels()) + " channel(s) of " + (png.depth() == CV_8U ? "8" : "other") +
                     " bit");
  }
  if (expected && png.size() != *expected) {
    throw InputError(fmt::format("{}: depth frame is {}x{}, expected {}x{} like the first", path.string(), png.cols,
                                 png.rows, expected->width, expected->height));
  }
  cv::Mat mm(png.size(), CV_16UC1);
  for (int v = 0; v < png.rows; ++v) {
    const auto* in = png.ptr<std::uint16_t>(v);
    auto* out = mm.ptr<std::uint16_t>(v);
    for (int u = 0; u < png.cols; ++u)
      out[u] = static_cast<std::uint16_t>((in[u] + kTumPerMillimetre / 2) / kTumPerMillimetre);
  }
  return mm;
}

cv::Mat ReadTumColour(const fs::path& path, std::optional<cv::Size> expected) {
  const std::string bytes = ReadImageBytesWithin(path, kMaxColourSide, "a colour PNG");
  const cv::Mat bgr = cv::imdecode(Bytes(bytes), cv::IMREAD_COLOR);
  if (bgr.empty()) throw InputError(path.string() + ": not a readable image (expected a colour PNG)");
  if (expected && bgr.size() != *expected) {
    throw InputError(fmt::format("{}: colour frame is {}x{}, expected {}x{} like the first", path.string(), bgr.cols,
                                 bgr.rows, expected->width, expected->height));
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

struct TumPair {
  ListedFrame depth, colour;
};

class TumSource : public FrameSource {
 public:
  TumSource(std::vector<TumPair> pairs, cv::Size depth_size, cv::Size colour_size)
      : pairs_(std::move(pairs)), depth_size_(depth_size), colour_size_(colour_size) {}
  std::int64_t expected_frames() const override { return static_cast<std::int64_t>(pairs_.size()); }
  std::optional<FramePair> Next() override {
    if (next_ >= pairs_.size()) return std::nullopt;
    const TumPair& p = pairs_[next_];
    FramePair frame;
    frame.source_number = static_cast<std::int64_t>(next_++);
    frame.depth.image = ReadTumDepth(p.depth.file, depth_size_);
    frame.depth.host_time_ns = p.depth.stamp_ns;
    frame.colour.image = ReadTumColour(p.colour.file, colour_size_);
    frame.colour.host_time_ns = p.colour.stamp_ns;
    return frame;
  }

 private:
  std::vector<TumPair> pairs_;
  cv::Size depth_size_, colour_size_;
  std::size_t next_ = 0;
};

}  // namespace

PlannedRecording PlanTumImport(const fs::path& dir, const TumImportOptions& options, std::vector<std::string>* notes) {
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a directory (expected a TUM RGB-D folder)");
  const std::vector<ListedFrame> depth = ReadList(dir, "depth.txt"), colour = ReadList(dir, "rgb.txt");
  if (depth.empty() || colour.empty()) {
    throw InputError((dir / (depth.empty() ? "depth.txt" : "rgb.txt")).string() + ": lists no frames");
  }
  std::vector<std::int64_t> depth_ns, colour_ns;
  for (const auto& f : depth) depth_ns.push_back(f.stamp_ns);
  for (const auto& f : colour) colour_ns.push_back(f.stamp_ns);
  std::vector<TumPair> pairs;
  int alone = 0;
  for (const StampPair& p : PairByStamp(depth_ns, colour_ns, std::llround(options.max_pair_gap_s * 1e9))) {
    if (p.depth < 0 || p.colour < 0) {
      ++alone;
      continue;
    }
    pairs.push_back({depth[static_cast<std::size_t>(p.depth)], colour[static_cast<std::size_t>(p.colour)]});
  }
  if (pairs.empty()) {
    throw InputError(fmt::format("{}: no depth frame has a colour frame within {} ms in rgb.txt",
                                 (dir / "depth.txt").string(), options.max_pair_gap_s * 1000));
  }
  if (notes) {
    notes->push_back(
        fmt::format("{} depth and {} colour frames listed: {} pairs within {} ms, {} left without a partner "
                    "(dropped, as associate.py drops them)",
                    depth.size(), colour.size(), pairs.size(), options.max_pair_gap_s * 1000, alone));
  }
  // Every file is read once now, so a bad one stops the import before anything is written.
  const cv::Size depth_size = ReadTumDepth(pairs.front().depth.file, std::nullopt).size();
  const cv::Size colour_size = ReadTumColour(pairs.front().colour.file, std::nullopt).size();
  for (const auto& p : pairs) ReadTumDepth(p.depth.file, depth_size), ReadTumColour(p.colour.file, colour_size);

  PlannedRecording planned;
  planned.file = ToString(options.purpose) + ".h5";
  RecordingHeader& h = planned.header;
  h.purpose = options.purpose;
  h.source = "tum";
  h.source_path = fs::absolute(dir).string();
  h.colour_size = colour_size;
  h.depth_size = depth_size;
  h.depth_units = DepthUnits::kMillimetre;
  planned.source = std::make_unique<TumSource>(std::move(pairs), depth_size, colour_size);
  return planned;
}

}  // namespace speckle
