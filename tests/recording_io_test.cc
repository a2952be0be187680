// The recording writer and reader round-trip frames bit for bit with every
// codec, keep clocks, series and accelerometer samples, and refuse to
// overwrite.
#include <gtest/gtest.h>

#include <random>

#include "pipeline/frame_feed.h"
#include "recorder/recording_reader.h"
#include "recorder/recording_writer.h"
#include "schemas/errors.h"
#include "test_util.h"

namespace speckle {
namespace {

using testing::ScratchDir;

RecordingHeader SmallHeader() {
  RecordingHeader h;
  h.purpose = RecordingPurpose::kDepthboard;
  h.source = "test";
  h.colour_size = cv::Size(64, 48);
  h.depth_size = cv::Size(32, 24);
  h.ir_size = cv::Size(32, 24);
  h.has_accel = true;
  h.scenario_json = R"({"seed": 3})";
  h.device_registration_json = R"({"const_shift": 200})";
  h.series = {{"truth/pose", {2, 3}, "a test series"}};
  return h;
}

FramePair RandomFrame(std::mt19937& rng, int index, const RecordingHeader& h) {
  FramePair f;
  f.source_number = 100 + index;
  f.colour.image = cv::Mat(h.colour_size->height, h.colour_size->width, CV_8UC3);
  cv::randu(f.colour.image, 0, 255);
  f.depth.image = cv::Mat(h.depth_size->height, h.depth_size->width, CV_16UC1);
  cv::randu(f.depth.image, 300, 1100);
  f.depth.image(cv::Rect(0, 0, 5, 5)) = 2047;
  if (index % 2 == 0) {  // IR only on every other frame: valid flags must say so
    f.ir.image = cv::Mat(h.ir_size->height, h.ir_size->width, CV_16UC1);
    cv::randu(f.ir.image, 0, 1023);
  }
  f.colour.device_timestamp = 1000u * index;
  f.depth.device_timestamp = 1000u * index + 7;
  f.colour.host_time_ns = 5'000'000'000LL + index;
  f.depth.host_time_ns = 5'000'000'001LL + index;
  f.accel = {{f.depth.host_time_ns, 42u, {26, 808, static_cast<std::int16_t>(index)}, 3, 1}};
  f.series["truth/pose"] = {1.0 * index, 2, 3, 4, 5, 6};
  return f;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

class CodecRoundTrip : public ::testing::TestWithParam<Codec> {};

TEST_P(CodecRoundTrip, FramesClocksAndSeriesReadBackIdentical) {
  ScratchDir dir;
  const auto path = dir / "r.h5";
  const RecordingHeader header = SmallHeader();
  std::mt19937 rng(7);
  std::vector<FramePair> written;
  {
    RecordingWriter writer(path, header, {GetParam(), 1, std::chrono::milliseconds(500)});
    for (int i = 0; i < 6; ++i) {
      written.push_back(RandomFrame(rng, i, header));
      FramePair copy = written.back();
      copy.colour.image = written.back().colour.image.clone();
      writer.Append(std::move(copy));
    }
    writer.Close();
  }
  const RecordingReader reader(path);
  EXPECT_TRUE(reader.closed_cleanly());
  ASSERT_EQ(reader.frame_count(), 6);
  EXPECT_EQ(reader.header().purpose, RecordingPurpose::kDepthboard);
  EXPECT_EQ(reader.header().scenario_json, header.scenario_json);
  EXPECT_EQ(reader.header().device_registration_json, header.device_registration_json);
  for (int i = 0; i < 6; ++i) {
    const FramePair read = reader.ReadFrame(i);
    EXPECT_TRUE(Identical(read.colour.image, written[i].colour.image)) << "colour frame " << i;
    EXPECT_TRUE(Identical(read.depth.image, written[i].depth.image)) << "depth frame " << i;
    EXPECT_EQ(read.ir.valid(), i % 2 == 0);
    if (i % 2 == 0) {
      EXPECT_TRUE(Identical(read.ir.image, written[i].ir.image)) << "ir frame " << i;
    }
    EXPECT_EQ(read.source_number, 100 + i);
    EXPECT_EQ(read.colour.device_timestamp, 1000u * i);
    EXPECT_EQ(read.depth.host_time_ns, 5'000'000'001LL + i);
  }
  const auto accel = reader.ReadAccel();
  ASSERT_EQ(accel.size(), 6u);
  EXPECT_EQ(accel[4].counts[2], 4);
  EXPECT_EQ(accel[4].counts[1], 808);
}

INSTANTIATE_TEST_SUITE_P(AllCodecs, CodecRoundTrip,
                         ::testing::Values(Codec::kSzip, Codec::kDeflate, Codec::kNone, Codec::kLz4),
                         [](const auto& info) { return ToString(info.param); });

TEST(RecordingWriter, RefusesToOverwrite) {
  ScratchDir dir;
  { RecordingWriter writer(dir / "r.h5", SmallHeader()); }
  EXPECT_THROW(RecordingWriter(dir / "r.h5", SmallHeader()), InputError);
}

TEST(RecordingWriter, RejectsFramesOfTheWrongSize) {
  ScratchDir dir;
  RecordingWriter writer(dir / "r.h5", SmallHeader());
  FramePair f;
  f.depth.image = cv::Mat(480, 640, CV_16UC1, cv::Scalar(700));
  try {
    writer.Append(f);
    FAIL() << "a 640x480 depth frame was accepted by a 32x24 recording";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected 32x24"), std::string::npos) << e.what();
  }
}

// The pipeline decodes what a recording's steps use: walls are cleaned from
// depth alone, boards detected in colour and paired with depth, IR
// chessboards detected in IR alone.
TEST(FrameFeed, DecodesOnlyTheImagesItsRecordingsStepsUse) {
  ScratchDir dir;
  const RecordingHeader header = SmallHeader();
  {
    RecordingWriter writer(dir / "r.h5", header, {Codec::kSzip, 1, std::chrono::milliseconds(500)});
    std::mt19937 rng(7);
    writer.Append(RandomFrame(rng, 0, header));
    writer.Close();
  }
  const auto first = [&](RecordingPurpose purpose) { return FrameFeed(dir / "r.h5", purpose).Next(); };
  const Frame wall = first(RecordingPurpose::kPlanar), board = first(RecordingPurpose::kDepthboard),
              ir = first(RecordingPurpose::kIrChessboard);
  EXPECT_TRUE(wall->colour.empty() && wall->ir.empty() && wall->raw.Present());
  EXPECT_TRUE(!board->colour.empty() && board->ir.empty() && board->raw.Present());
  EXPECT_TRUE(ir->colour.empty() && !ir->ir.empty() && !ir->raw.Present());
  EXPECT_EQ(wall->time_s, board->time_s);  // clocks are read whatever is decoded
}

TEST(RecordingWriter, AbsentDepthFramesReadAsInvalid) {
  ScratchDir dir;
  RecordingHeader h = SmallHeader();
  {
    RecordingWriter writer(dir / "r.h5", h);
    FramePair colour_only;
    colour_only.colour.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(1, 2, 3));
    colour_only.series["truth/pose"] = std::vector<double>(6, 0.0);
    writer.Append(colour_only);
  }
  const RecordingReader reader(dir / "r.h5");
  const FramePair f = reader.ReadFrame(0);
  EXPECT_TRUE(f.colour.valid());
  EXPECT_FALSE(f.depth.valid());
  EXPECT_EQ(reader.ReadClock(1).valid.at(0), 0);
}

}  // namespace
}  // namespace speckle
