// The live recorder's device code through libfreenect's own API, played by
// fakenect (libfreenect's recorded-dump stand-in for a Kinect): depth and
// colour still arrive through the callbacks, pair and record. Fakenect plays
// only RGB and depth (its freenect_find_video_mode asserts on IR formats), so
// the IR step is tested through the callback seam in freenect_ir_test.
#include <gtest/gtest.h>

#include <cstdio>

#include "recorder/recording_reader.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

const fs::path kFakenectLibraryDir = "/usr/lib/x86_64-linux-gnu/fakenect";

std::uint32_t ColourTimestamp(int i) { return 100 + 2'000'000U * i; }  // 30 Hz at 60 MHz

// A fakenect dump of `frames` colour + depth frames at 30 Hz; colour frame i
// is filled with the value i, so a recorded pair shows which frame it holds.
void WriteDump(const fs::path& dir, int frames) {
  fs::create_directories(dir);
  std::ofstream index(dir / "INDEX.txt");
  for (int i = 0; i < frames; ++i) {
    char colour[64], depth[64];
    std::snprintf(colour, sizeof colour, "r-%.6f-%u-.ppm", 1.0 + i / 30.0, ColourTimestamp(i));
    std::snprintf(depth, sizeof depth, "d-%.6f-%u-.pgm", 1.001 + i / 30.0, ColourTimestamp(i) + 100);
    std::ofstream(dir / colour, std::ios::binary) << "P6 640 480 255\n"
                                                  << std::string(640 * 480 * 3, static_cast<char>(i));
    std::ofstream(dir / depth, std::ios::binary) << "P5 640 480 65535\n" << std::string(640 * 480 * 2, '\x02');
    index << colour << "\n" << depth << "\n";
  }
}

TEST(FreenectDevice, DepthAndColourRecordThroughFakenectPlayback) {
  if (!fs::exists(kFakenectLibraryDir / "libfreenect.so.0.5"))
    GTEST_SKIP() << "fakenect (libfreenect0.5) not installed";
  ScratchDir scratch;
  WriteDump(scratch / "dump", 10);
  const std::string command =
      "LD_LIBRARY_PATH=" + kFakenectLibraryDir.string() + " FAKENECT_PATH=" + (scratch / "dump").string() + " " +
      (BinDir() / "record-session").string() + " freenect --purpose depthboard --duration 1 --out " +
      (scratch / "played").string() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  while (pipe && fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(pipe ? pclose(pipe) : -1, 0) << output;

  const RecordingReader reader(scratch / "played" / "depthboard.h5");
  EXPECT_EQ(reader.header().source, "freenect");
  ASSERT_GE(reader.frame_count(), 10) << output;
  std::int64_t with_colour = 0;
  for (std::int64_t i = 0; i < reader.frame_count(); ++i) {
    const FramePair pair = reader.ReadFrame(i);
    ASSERT_TRUE(pair.depth.valid()) << "pair " << i;
    EXPECT_EQ(pair.depth.image.at<std::uint16_t>(0, 0), 0x0202) << "pair " << i;
    if (!pair.colour.valid()) continue;
    ++with_colour;
    // The colour frame a pair holds is the one its timestamp names.
    const int shown = pair.colour.image.at<cv::Vec3b>(240, 320)[0];
    EXPECT_EQ(pair.colour.device_timestamp, ColourTimestamp(shown)) << "pair " << i;
    EXPECT_EQ(pair.depth.device_timestamp, ColourTimestamp(shown) + 100) << "pair " << i;
  }
  // Each depth frame follows its colour frame in the dump: all but the first may pair.
  EXPECT_GE(with_colour, reader.frame_count() - 1);
}

}  // namespace
}  // namespace speckle
