// The real libfreenect dumps and toolbox frame folders in ../shared/data
// import through the command-line tool, frames read back bit-identical to an
// independent decode, and the byte order is right (valid raw values lie in
// about 300..1100).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "recorder/recording_reader.h"
#include "schemas/session_manifest.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

// Decodes a 640x480 16-bit PGM by hand: header of `header_bytes`, then data.
cv::Mat DecodeByHand(const fs::path& path, std::size_t header_bytes, bool little_endian) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), {}};
  cv::Mat image(480, 640, CV_16UC1);
  for (int i = 0; i < 640 * 480; ++i) {
    const auto lo = static_cast<unsigned char>(bytes[header_bytes + 2 * i + (little_endian ? 0 : 1)]);
    const auto hi = static_cast<unsigned char>(bytes[header_bytes + 2 * i + (little_endian ? 1 : 0)]);
    image.ptr<std::uint16_t>()[i] = static_cast<std::uint16_t>(hi << 8 | lo);
  }
  return image;
}

// Share of valid (non-2047) pixels whose raw value lies in [300, 1100].
double ShareInKinectRange(const cv::Mat& raw) {
  int valid = 0, in_range = 0;
  for (int i = 0; i < static_cast<int>(raw.total()); ++i) {
    const int v = raw.ptr<std::uint16_t>()[i];
    if (v == 2047) continue;
    ++valid;
    in_range += v >= 300 && v <= 1100;
  }
  return valid ? double(in_range) / valid : 0.0;
}

std::vector<std::string> IndexLines(const fs::path& dump, char kind) {
  std::ifstream in(dump / "INDEX.txt");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] == kind) lines.push_back(line);
  return lines;
}

TEST(FakenectImport, RealDumpRoundTripsBitIdenticalInLittleEndian) {
  ScratchDir dir;
  const fs::path dump = SharedData() / "fakenect_openiss_depth";
  const auto result = RunTool("record-session", "fakenect:" + dump.string() + " --out " + (dir / "s").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const SessionManifest manifest = ReadSessionManifest(dir / "s");
  ASSERT_EQ(manifest.recordings.size(), 1u);
  EXPECT_FALSE(manifest.rig.has_value());
  const RecordingReader reader(dir / "s" / manifest.recordings[0].file);
  const auto depth_files = IndexLines(dump, 'd');
  ASSERT_EQ(reader.frame_count(), static_cast<std::int64_t>(depth_files.size()));
  EXPECT_FALSE(reader.header().colour_size.has_value()) << "the dump has no colour frames";
  for (std::size_t i = 0; i < depth_files.size(); ++i) {
    const FramePair frame = reader.ReadFrame(static_cast<std::int64_t>(i));
    const cv::Mat expected = DecodeByHand(dump / depth_files[i], 17, /*little_endian=*/true);
    ASSERT_EQ(cv::norm(frame.depth.image, expected, cv::NORM_INF), 0) << depth_files[i];
    EXPECT_GT(ShareInKinectRange(frame.depth.image), 0.99) << depth_files[i];
    EXPECT_LT(ShareInKinectRange(DecodeByHand(dump / depth_files[i], 17, false)), 0.5)
        << "big-endian reading should look wrong, or the range test proves nothing";
  }
  EXPECT_EQ(reader.ReadAccel().size(), IndexLines(dump, 'a').size());
  const auto clock = reader.ReadClock(1);
  EXPECT_EQ(clock.device_timestamp.front(), 1349758830u);
  EXPECT_EQ(clock.host_time_ns.front(), 1483969349177955000LL);
}

TEST(FakenectImport, KeepsDeviceRegistration) {
  ScratchDir dir;
  const auto result = RunTool("record-session", "fakenect:" + (SharedData() / "fakenect_openiss_test").string() +
                                                    " --out " + (dir / "s").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const RecordingReader reader(dir / "s" / "free.h5");
  const auto registration = nlohmann::json::parse(reader.header().device_registration_json);
  EXPECT_EQ(registration.at("reg_info").at("ax"), 1830);
  EXPECT_EQ(registration.at("const_shift"), 200);
}

struct FolderCase {
  std::string folder;
  std::string rig_flags;
  int colour_frames, paired_frames_with_depth, planar_frames;
  cv::Size colour_size;
};

class FramesImport : public ::testing::TestWithParam<FolderCase> {};

TEST_P(FramesImport, ToolboxFolderImportsWithBigEndianDepth) {
  const FolderCase& c = GetParam();
  ScratchDir dir;
  const auto result = RunTool("record-session", "frames:" + (SharedData() / c.folder).string() + " " + c.rig_flags +
                                                    " --out " + (dir / "s").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const SessionManifest manifest = ReadSessionManifest(dir / "s");
  ASSERT_TRUE(manifest.rig.has_value());
  const RecordingReader board(dir / "s" / "depthboard.h5");
  EXPECT_EQ(*board.header().colour_size, c.colour_size);
  const auto colour = board.ReadClock(0), depth = board.ReadClock(1);
  EXPECT_EQ(std::count(colour.valid.begin(), colour.valid.end(), 1), c.colour_frames);
  EXPECT_EQ(std::count(depth.valid.begin(), depth.valid.end(), 1), c.paired_frames_with_depth);
  const RecordingReader planar(dir / "s" / "planar.h5");
  EXPECT_EQ(planar.frame_count(), c.planar_frames);
  for (std::int64_t i = 0; i < planar.frame_count(); ++i) {
    EXPECT_GT(ShareInKinectRange(planar.ReadFrame(i).depth.image), 0.99) << "planar frame " << i;
  }
  // Spot-check one frame against an independent decode of its file.
  const FramePair first = board.ReadFrame(0);
  char name[32];
  std::snprintf(name, sizeof name, "%04lld-d.pgm", static_cast<long long>(first.source_number));
  EXPECT_EQ(cv::norm(first.depth.image, DecodeByHand(SharedData() / c.folder / name, 16, false), cv::NORM_INF), 0);
}

INSTANTIATE_TEST_SUITE_P(RealData, FramesImport,
                         ::testing::Values(FolderCase{"herrera_kinect_calib",
                                                      "--squares 9x7 --square-size 0.04 --outline larger_board",
                                                      54,
                                                      39,
                                                      16,
                                                      {1280, 1024}},
                                           FolderCase{"xiang_kinect_smallset/smallset",
                                                      "--squares 11x8 --square-size 0.031 --outline larger_board",
                                                      16,
                                                      16,
                                                      5,
                                                      {640, 480}}),
                         [](const auto& info) {
                           return info.index == 0 ? std::string("Herrera") : std::string("Xiang");
                         });

}  // namespace
}  // namespace speckle
