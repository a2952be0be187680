#include "recorder/sources/rosbag_source.h"

#include <fmt/format.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <cstring>
#include <map>
#include <opencv2/imgproc.hpp>
#include <set>

#include "recorder/sources/stamp_pairing.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

enum class Stream { kDepth, kColour, kIr };

const std::map<Stream, std::set<std::string>> kEncodings{{Stream::kDepth, {"16UC1", "32FC1"}},
                                                         {Stream::kColour, {"rgb8", "bgr8", "bayer_grbg8"}},
                                                         {Stream::kIr, {"mono16"}}};

int BytesPerPixel(const std::string& encoding) {
  if (encoding == "32FC1") return 4;
  if (encoding == "16UC1" || encoding == "mono16") return 2;
  if (encoding == "rgb8" || encoding == "bgr8") return 3;
  return 1;  // bayer_grbg8
}

// What the first pass learns of one topic.
struct TopicScan {
  std::string topic, encoding;
  cv::Size size;
  std::vector<std::int64_t> stamps_ns;
  std::uint16_t min_value = 65535, max_value = 0;  // 16UC1 only
  std::int64_t zeros = 0, at_2047 = 0;
};

std::string Where(const fs::path& bag, const std::string& topic) { return bag.string() + ": topic " + topic; }

// The message's pixels as a Mat over its own rows (step may pad them); checks
// the encoding, size and buffer against what the topic's first message had.
cv::Mat Pixels(const fs::path& bag, const std::string& topic, Stream stream, const sensor_msgs::Image& m,
               std::size_t index, const TopicScan* first) {
  const std::string at = fmt::format("{} message {}", Where(bag, topic), index);
  if (!kEncodings.at(stream).count(m.encoding)) {
    std::string known;
    for (const auto& e : kEncodings.at(stream)) known += (known.empty() ? "" : ", ") + e;
    throw InputError(fmt::format("{}: encoding \"{}\" is not one this import reads ({} here)", at, m.encoding, known));
  }
  if (first && m.encoding != first->encoding) {
    throw InputError(
        fmt::format("{}: encoding {} where the topic's first message has {}", at, m.encoding, first->encoding));
  }
  const cv::Size size(static_cast<int>(m.width), static_cast<int>(m.height));
  if (first && size != first->size) {
    throw InputError(fmt::format("{}: image is {}x{}, expected {}x{} like the topic's first message", at, size.width,
                                 size.height, first->size.width, first->size.height));
  }
  const std::size_t row = static_cast<std::size_t>(m.width) * BytesPerPixel(m.encoding);
  if (m.width == 0 || m.height == 0 || m.step < row || m.data.size() < static_cast<std::size_t>(m.step) * m.height) {
    throw InputError(fmt::format("{}: {}x{} {} image with step {} and {} bytes of data does not hold its pixels", at,
                                 m.width, m.height, m.encoding, m.step, m.data.size()));
  }
  if (m.is_bigendian && BytesPerPixel(m.encoding) > 1) {
    throw InputError(at + ": big-endian pixels (is_bigendian = 1) are not read; republish them little-endian");
  }
  const int type = m.encoding == "32FC1"            ? CV_32FC1
                   : BytesPerPixel(m.encoding) == 2 ? CV_16UC1
                   : BytesPerPixel(m.encoding) == 3 ? CV_8UC3
                                                    : CV_8UC1;
  return cv::Mat(size, type, const_cast<std::uint8_t*>(m.data.data()), m.step);
}

// A frame as the recording stores it: depth CV_16UC1 in the recording's
// units, colour CV_8UC3 RGB, IR CV_16UC1.
cv::Mat Converted(const cv::Mat& pixels, const std::string& encoding) {
  cv::Mat out;
  if (encoding == "32FC1") {  // metres; NaN, inf and 0 are no reading
    out.create(pixels.size(), CV_16UC1);
    for (int v = 0; v < pixels.rows; ++v) {
      const auto* in = pixels.ptr<float>(v);
      auto* o = out.ptr<std::uint16_t>(v);
      for (int u = 0; u < pixels.cols; ++u) {
        const double mm = std::round(static_cast<double>(in[u]) * 1000);
        o[u] = std::isfinite(mm) && mm >= 1 && mm <= 65535 ? static_cast<std::uint16_t>(mm) : 0;
      }
    }
  } else if (encoding == "bgr8") {
    cv::cvtColor(pixels, out, cv::COLOR_BGR2RGB);
  } else if (encoding == "bayer_grbg8") {
    // OpenCV names Bayer patterns by their second row: ROS's GRBG is its GB
    // (as cv_bridge converts it).
    cv::cvtColor(pixels, out, cv::COLOR_BayerGB2RGB);
  } else {
    out = pixels.clone();
  }
  return out;
}

std::int64_t StampNs(const sensor_msgs::Image& m, const rosbag::MessageInstance& instance) {
  const ros::Time stamp = m.header.stamp.isZero() ? instance.getTime() : m.header.stamp;
  return static_cast<std::int64_t>(stamp.toNSec());
}

// Whether a message's bytes hold a whole sensor_msgs/Image: every length
// prefix (frame_id, encoding, data) within the bytes that follow it. ROS's
// deserializer trusts them: a data length claiming 4 GB allocated 4 GB, and
// bytes of another type threw "Buffer Overrun" naming nothing.
bool HoldsAnImage(const rosbag::MessageInstance& m) {
  std::vector<std::uint8_t> bytes(m.size());
  ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  m.write(out);
  std::size_t at = 0;
  const auto skip = [&](std::size_t n) { return (at += n) <= bytes.size(); };
  const auto string = [&] {
    if (at + 4 > bytes.size()) return false;
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + at, 4);
    return skip(4) && skip(length);
  };
  // header (seq, stamp, frame_id), height, width, encoding, is_bigendian, step, data
  return skip(12) && string() && skip(8) && string() && skip(5) && string() && at == bytes.size();
}

sensor_msgs::ImageConstPtr AsImage(const fs::path& bag, const rosbag::MessageInstance& m) {
  if (m.getDataType() == "sensor_msgs/Image" && !HoldsAnImage(m))
    throw InputError(
        fmt::format("{}: a message of {} bytes at {:.3f} s is not a whole sensor_msgs/Image (its "
                    "lengths overrun it)",
                    Where(bag, m.getTopic()), m.size(), m.getTime().toSec()));
  auto image = m.instantiate<sensor_msgs::Image>();
  if (!image) {
    throw InputError(
        fmt::format("{}: holds {} messages, expected sensor_msgs/Image", Where(bag, m.getTopic()), m.getDataType()));
  }
  return image;
}

TopicScan ScanTopic(rosbag::Bag& bag, const fs::path& path, const std::string& topic, Stream stream) {
  TopicScan scan;
  scan.topic = topic;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  std::size_t index = 0;
  for (const rosbag::MessageInstance& m : view) {
    const auto image = AsImage(path, m);
    const cv::Mat pixels = Pixels(path, topic, stream, *image, index, index ? &scan : nullptr);
    if (index++ == 0) scan.encoding = image->encoding, scan.size = pixels.size();
    scan.stamps_ns.push_back(StampNs(*image, m));
    if (image->encoding != "16UC1") continue;
    double min = 0, max = 0;
    cv::minMaxLoc(pixels, &min, &max);
    scan.min_value = std::min<std::uint16_t>(scan.min_value, static_cast<std::uint16_t>(min));
    scan.max_value = std::max<std::uint16_t>(scan.max_value, static_cast<std::uint16_t>(max));
    scan.zeros += pixels.total() - cv::countNonZero(pixels);
    scan.at_2047 += cv::countNonZero(pixels == 2047);
  }
  return scan;
}

// Opens `topic` in turn for each frame asked for, in any order (bags are
// read forward, so asking for an earlier frame starts over).
class TopicCursor {
 public:
  TopicCursor(rosbag::Bag& bag, fs::path path, std::string topic)
      : bag_(bag), path_(std::move(path)), topic_(std::move(topic)) {}
  sensor_msgs::ImageConstPtr At(std::size_t index, std::int64_t* stamp_ns) {
    if (!view_ || index < position_) {
      view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topic_));
      it_ = view_->begin();
      position_ = 0;
    }
    for (; position_ < index; ++position_) ++it_;
    auto image = AsImage(path_, *it_);
    *stamp_ns = StampNs(*image, *it_);
    return image;
  }

 private:
  rosbag::Bag& bag_;
  fs::path path_;
  std::string topic_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  std::size_t position_ = 0;
};

class RosbagSource : public FrameSource {
 public:
  RosbagSource(const fs::path& path, std::vector<StampPair> pairs, TopicScan first, std::optional<TopicScan> second)
      : path_(path), pairs_(std::move(pairs)), first_(std::move(first)), second_(std::move(second)) {
    bag_.open(path.string(), rosbag::bagmode::Read);
    first_cursor_ = std::make_unique<TopicCursor>(bag_, path_, first_.topic);
    if (second_) second_cursor_ = std::make_unique<TopicCursor>(bag_, path_, second_->topic);
  }
  std::int64_t expected_frames() const override { return static_cast<std::int64_t>(pairs_.size()); }
  std::optional<FramePair> Next() override {
    if (next_ >= pairs_.size()) return std::nullopt;
    const StampPair& p = pairs_[next_];
    FramePair frame;
    ++next_;
    // Named by message, as rqt_bag and rosbag's View count them, not by the
    // stamp order pairing sorts them into.
    frame.source_number = p.depth >= 0 ? p.depth : p.colour;
    // The first topic is depth (IR for ir_chessboard), the second colour.
    if (p.depth >= 0) Read(*first_cursor_, first_, static_cast<std::size_t>(p.depth), second_ ? frame.depth : frame.ir);
    if (p.colour >= 0) Read(*second_cursor_, *second_, static_cast<std::size_t>(p.colour), frame.colour);
    return frame;
  }

 private:
  void Read(TopicCursor& cursor, const TopicScan& scan, std::size_t index, StreamFrame& into) {
    std::int64_t stamp_ns = 0;
    const auto image = cursor.At(index, &stamp_ns);
    const Stream stream = !second_ ? Stream::kIr : &scan == &first_ ? Stream::kDepth : Stream::kColour;
    into.image = Converted(Pixels(path_, scan.topic, stream, *image, index, &scan), scan.encoding);
    into.host_time_ns = stamp_ns;
  }

  fs::path path_;
  rosbag::Bag bag_;
  std::vector<StampPair> pairs_;
  TopicScan first_;
  std::optional<TopicScan> second_;
  std::unique_ptr<TopicCursor> first_cursor_, second_cursor_;
  std::size_t next_ = 0;
};

// The first camera_info beside an image topic: "/camera/rgb/image_color" ->
// "/camera/rgb/camera_info". It must describe the images it stands beside.
KnownIntrinsics CameraInfoBeside(rosbag::Bag& bag, const fs::path& path, const TopicScan& image) {
  const std::string topic = image.topic.substr(0, image.topic.rfind('/') + 1) + "camera_info";
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const auto info = m.instantiate<sensor_msgs::CameraInfo>();
    if (!info)
      throw InputError(
          fmt::format("{}: holds {} messages, expected sensor_msgs/CameraInfo", Where(path, topic), m.getDataType()));
    if (info->distortion_model != "plumb_bob" && !(info->distortion_model.empty() && info->D.empty())) {
      throw InputError(fmt::format("{}: distortion model \"{}\"; only plumb_bob (k1 k2 p1 p2 k3) is kept",
                                   Where(path, topic), info->distortion_model));
    }
    if (!(info->K[0] > 0 && info->K[4] > 0) || info->width == 0 || info->height == 0) {
      throw InputError(Where(path, topic) +
                       ": camera_info has no focal length or size (an uncalibrated camera); "
                       "import without --use-camera-info to calibrate it");
    }
    KnownIntrinsics k;
    k.width = static_cast<int>(info->width), k.height = static_cast<int>(info->height);
    k.fx = info->K[0], k.fy = info->K[4], k.cx = info->K[2], k.cy = info->K[5];
    for (std::size_t i = 0; i < 5 && i < info->D.size(); ++i) k.distortion[i] = info->D[i];
    if (k.width != image.size.width || k.height != image.size.height) {
      throw InputError(fmt::format("{}: camera_info is for {}x{} images, but {} holds {}x{}", Where(path, topic),
                                   k.width, k.height, image.topic, image.size.width, image.size.height));
    }
    return CheckedIntrinsics(k, Where(path, topic) + ": camera_info");
  }
  throw InputError(Where(path, topic) + ": no camera_info messages, which --use-camera-info needs");
}

std::vector<StampPair> Pair(const fs::path& path, const TopicScan& depth, const TopicScan& colour,
                            const RosbagImportOptions& options, std::vector<std::string>* notes) {
  auto pairs = PairByStamp(depth.stamps_ns, colour.stamps_ns, std::llround(options.max_pair_gap_s * 1e9));
  std::int64_t alone = 0;
  for (const auto& p : pairs) alone += p.depth < 0 || p.colour < 0;
  if (alone == 0) return pairs;
  const std::string message =
      fmt::format("{} of {} {} and {} {} frames have no partner within {} ms", alone, depth.stamps_ns.size(),
                  depth.topic, colour.stamps_ns.size(), colour.topic, options.max_pair_gap_s * 1000);
  if (!options.allow_unpaired) {
    throw InputError(path.string() + ": " + message + " (use --allow-unpaired to keep them as single-stream frames)");
  }
  if (notes) notes->push_back(message + "; kept as single-stream frames");
  return pairs;
}

std::string TopicsOf(rosbag::Bag& bag) {
  rosbag::View all(bag);
  std::string out;
  for (const auto* c : all.getConnections()) out += (out.empty() ? "" : ", ") + c->topic + " (" + c->datatype + ")";
  return out.empty() ? "none" : out;
}

TopicScan ScanOrExplain(rosbag::Bag& bag, const fs::path& path, const std::string& topic, Stream stream,
                        const char* option) {
  TopicScan scan = ScanTopic(bag, path, topic, stream);
  if (scan.stamps_ns.empty()) {
    throw InputError(fmt::format("{}: no messages; the bag has {}. Choose the topic with {}", Where(path, topic),
                                 TopicsOf(bag), option));
  }
  return scan;
}

}  // namespace

std::optional<DepthUnits> DetectDepthUnits(std::uint16_t max_value, std::int64_t zeros, std::int64_t at_2047,
                                           std::string* why) {
  if (max_value > 2047) {
    *why = fmt::format("values up to {}, beyond 11 bits: millimetres", max_value);
    return DepthUnits::kMillimetre;
  }
  if (at_2047 > 0 && zeros == 0) {
    *why = "2047 marks missing readings and no value is 0: libfreenect's raw 11-bit values";
    return DepthUnits::kRaw11Bit;
  }
  if (zeros > 0) {
    *why = "no value beyond 11 bits, and 0 marks missing readings: millimetres (REP 118)";
    return DepthUnits::kMillimetre;
  }
  *why = "no pixel is 0 (REP 118's no reading) or 2047 (libfreenect's), and no value is beyond 11 bits";
  return std::nullopt;
}

namespace {

// The depth topic's units: stated, implied by the encoding, or read from the
// values; refused when the values fit both conventions.
DepthUnits DepthUnitsOf(const fs::path& path, const TopicScan& depth, const RosbagImportOptions& options,
                        std::vector<std::string>* notes) {
  std::string why = "stated by --depth-units";
  std::optional<DepthUnits> units = options.depth_units;
  if (depth.encoding == "32FC1") {
    why = "32FC1 metres, stored as millimetres";
    units = DepthUnits::kMillimetre;
  } else if (!units) {
    units = DetectDepthUnits(depth.max_value, depth.zeros, depth.at_2047, &why);
  }
  if (!units) {
    throw InputError(
        fmt::format("{}: 16UC1 depth whose units cannot be told: {}; its values {}-{} fit both raw 11-bit "
                    "values and millimetres. State them with --depth-units raw_11bit or millimetre",
                    Where(path, depth.topic), why, depth.min_value, depth.max_value));
  }
  if (notes)
    notes->push_back(fmt::format("{}: {} depth in {}: {}", depth.topic, depth.encoding, ToString(*units), why));
  return *units;
}

}  // namespace

RosbagImport PlanRosbagImport(const fs::path& path, const RosbagImportOptions& options,
                              std::vector<std::string>* notes) {
  if (!fs::is_regular_file(path)) throw InputError(path.string() + ": no such file (expected a ROS 1 .bag)");
  rosbag::Bag bag;
  try {
    bag.open(path.string(), rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw InputError(path.string() + ": not a readable ROS 1 bag: " + e.what());
  }
  RosbagImport out;
  PlannedRecording& planned = out.recording;
  RecordingHeader& h = planned.header;
  h.purpose = options.purpose;
  h.source = "rosbag";
  h.source_path = fs::absolute(path).string();
  std::vector<StampPair> pairs;
  std::optional<TopicScan> second;
  TopicScan first;
  try {
    if (options.purpose == RecordingPurpose::kIrChessboard) {
      first = ScanOrExplain(bag, path, options.ir_topic, Stream::kIr, "--ir-topic");
      h.ir_size = first.size;
      for (std::size_t i = 0; i < first.stamps_ns.size(); ++i)
        pairs.push_back({static_cast<int>(i), -1, first.stamps_ns[i]});
    } else {
      first = ScanOrExplain(bag, path, options.depth_topic, Stream::kDepth, "--depth-topic");
      second = ScanOrExplain(bag, path, options.colour_topic, Stream::kColour, "--colour-topic");
      pairs = Pair(path, first, *second, options, notes);
      h.depth_size = first.size;
      h.colour_size = second->size;
      out.depth_units = DepthUnitsOf(path, first, options, notes);
      h.depth_units = out.depth_units;
      if (options.use_camera_info) {
        out.colour_intrinsics = CameraInfoBeside(bag, path, *second);
        out.depth_intrinsics = CameraInfoBeside(bag, path, first);
      }
    }
  } catch (const rosbag::BagException& e) {
    throw InputError(path.string() + ": the bag could not be read: " + e.what());
  }
  if (notes) notes->push_back(fmt::format("{} frames from {}", pairs.size(), path.filename().string()));
  planned.file = ToString(options.purpose) + ".h5";
  planned.source = std::make_unique<RosbagSource>(path, std::move(pairs), std::move(first), std::move(second));
  return out;
}

}  // namespace speckle
