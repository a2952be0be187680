#include "recorder/sources/frames_dir_source.h"

#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>

#include "recorder/sources/colour_image.h"
#include "recorder/sources/pnm.h"
#include "schemas/decimal_text.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

struct NumberedFrame {
  std::int64_t number = 0;
  fs::path colour;
  fs::path depth;
};

// Frame numbers are counters; 15 digits leave room for any recording.
constexpr std::int64_t kMaxFrameNumber = 999'999'999'999'999;

const PnmExpectation kDepthPgm{{640, 480}, {2047, 2048}};

cv::Mat ReadColour(const fs::path& path) { return ReadColourImage(path); }

class FramesDirSource : public FrameSource {
 public:
  FramesDirSource(std::vector<NumberedFrame> frames, std::optional<cv::Size> colour_size)
      : frames_(std::move(frames)), colour_size_(colour_size) {}
  std::int64_t expected_frames() const override { return static_cast<std::int64_t>(frames_.size()); }
  std::optional<FramePair> Next() override {
    if (next_ >= frames_.size()) return std::nullopt;
    const NumberedFrame& f = frames_[next_++];
    FramePair pair;
    pair.source_number = f.number;
    if (!f.colour.empty()) {
      pair.colour.image = ReadColour(f.colour);
      if (pair.colour.image.size() != *colour_size_) {
        throw InputError(f.colour.string() + ": colour frame is " + std::to_string(pair.colour.image.cols) + "x" +
                         std::to_string(pair.colour.image.rows) + ", expected " + std::to_string(colour_size_->width) +
                         "x" + std::to_string(colour_size_->height) + " like the first colour frame");
      }
    }
    if (!f.depth.empty()) pair.depth.image = ReadPgm16(f.depth, ByteOrder::kBigEndian, kDepthPgm);
    return pair;
  }

 private:
  std::vector<NumberedFrame> frames_;
  std::optional<cv::Size> colour_size_;
  std::size_t next_ = 0;
};

PlannedRecording Plan(std::vector<NumberedFrame> frames, RecordingPurpose purpose, const fs::path& dir) {
  PlannedRecording planned;
  planned.file = ToString(purpose) + ".h5";
  RecordingHeader& h = planned.header;
  h.purpose = purpose;
  h.source = "frames";
  h.source_path = fs::absolute(dir).string();
  h.depth_units = DepthUnits::kRaw11Bit;
  std::optional<cv::Size> colour_size;
  for (const auto& f : frames) {
    if (!f.colour.empty() && !colour_size) colour_size = ReadColour(f.colour).size();
    if (!f.depth.empty()) h.depth_size = kDepthPgm.size;
  }
  h.colour_size = colour_size;
  // Check every depth frame's header now, so a bad file stops the import
  // before anything is written.
  for (const auto& f : frames)
    if (!f.depth.empty()) ReadPgm16(f.depth, ByteOrder::kBigEndian, kDepthPgm);
  planned.source = std::make_unique<FramesDirSource>(std::move(frames), colour_size);
  return planned;
}

}  // namespace

std::vector<PlannedRecording> PlanFramesImport(const fs::path& dir, const FramesImportOptions& options,
                                               std::vector<std::string>* notes) {
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a directory (expected a folder of frames)");
  // "0012-c1.jpg", "0012-d.pgm", "wall-6-d.pgm": an optional prefix, a number, the stream.
  static const std::regex kName(R"(^(.*?)(\d+)-(c1|d)\.(jpg|jpeg|png|pgm)$)", std::regex::icase);
  std::map<std::pair<std::string, std::int64_t>, NumberedFrame> by_number;
  int ignored = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (!entry.is_regular_file() || !std::regex_match(name, m, kName)) {
      ++ignored;
      continue;
    }
    const bool is_depth = m[3] == "d";
    const bool is_pgm = m[4].str() == "pgm";
    if (is_depth != is_pgm) {
      throw InputError(entry.path().string() + ": " +
                       (is_depth ? "depth frames must be .pgm" : "colour frames must be .jpg or .png"));
    }
    const auto number = ParseDecimal(m[2].str(), kMaxFrameNumber);
    if (!number) {
      throw InputError(entry.path().string() + ": frame number " + m[2].str() + " is out of range (at most " +
                       std::to_string(kMaxFrameNumber) + ")");
    }
    NumberedFrame& f = by_number[{m[1], *number}];
    f.number = *number;
    (is_depth ? f.depth : f.colour) = entry.path();
  }
  if (by_number.empty()) {
    throw InputError(dir.string() + ": holds no NNNN-c1.jpg or NNNN-d.pgm frames");
  }
  std::vector<NumberedFrame> paired, depth_only;
  for (auto& [key, f] : by_number) {
    const bool goes_apart = options.depth_only_purpose && f.colour.empty();
    (goes_apart ? depth_only : paired).push_back(f);
  }
  if (notes) {
    int colour_only = 0, depth_alone = 0;
    for (const auto& [key, f] : by_number) {
      colour_only += f.depth.empty();
      depth_alone += f.colour.empty();
    }
    notes->push_back(std::to_string(by_number.size()) + " numbered frames: " + std::to_string(colour_only) +
                     " colour only, " + std::to_string(depth_alone) + " depth only; " + std::to_string(ignored) +
                     " other files ignored");
  }
  std::vector<PlannedRecording> plans;
  if (!paired.empty()) plans.push_back(Plan(std::move(paired), options.paired_purpose, dir));
  if (!depth_only.empty()) plans.push_back(Plan(std::move(depth_only), *options.depth_only_purpose, dir));
  return plans;
}

}  // namespace speckle
