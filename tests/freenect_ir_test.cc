// The live recorder's IR step (`record-session freenect --purpose
// ir_chessboard`) without a Kinect. libfreenect's fakenect cannot play IR
// (its freenect_find_video_mode asserts on any format but RGB), so a test
// double stands in for the device's callbacks only: it renders IR views of
// the chessboard with the simulator and hands them to the real
// FreenectFrameFeed exactly as libfreenect would (8-bit, 640x488, 60 MHz
// timestamps, from its own thread). The recorder, queue and HDF5 writer are
// the real ones, and run-pipeline calibrates the depth camera from the result.
#include <gtest/gtest.h>

#include <cstdio>
#include <thread>

#include "recorder/recording_reader.h"
#include "recorder/session_recorder.h"
#include "recorder/sources/freenect_frame_feed.h"
#include "recorder/sources/sim_source.h"
#include "schemas/errors.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

const cv::Size kKinectIrModeSize{640, 488};  // FREENECT_VIDEO_IR_8BIT at FREENECT_RESOLUTION_MEDIUM

// One IR frame as libfreenect delivers it: the 480 image rows on top, then 8
// more rows the depth image does not have (saturated here, so a crop that
// keeps them shows).
std::vector<std::uint8_t> IrModeBuffer(const cv::Mat& ir_image_8bit) {
  cv::Mat buffer(kKinectIrModeSize, CV_8UC1, cv::Scalar(255));
  ir_image_8bit.copyTo(buffer(cv::Rect({0, 0}, ir_image_8bit.size())));
  return {buffer.datastart, buffer.dataend};
}

// The test double: a Kinect's video callbacks, playing `frames` (8-bit, 640x480)
// at the device clock `ticks`, then the end of the stream.
std::thread PlayIrCallbacks(FreenectFrameFeed& feed, std::vector<cv::Mat> frames, std::vector<std::uint32_t> ticks) {
  return std::thread([&feed, frames = std::move(frames), ticks = std::move(ticks)] {
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const std::vector<std::uint8_t> buffer = IrModeBuffer(frames[i]);
      feed.OnVideo(buffer.data(), ticks[i]);
    }
    feed.EndOfStream();
  });
}

FreenectFeedOptions IrFeedOptions() {
  FreenectFeedOptions options;
  options.streams.video = FreenectVideo::kIr;
  options.streams.video_size = kKinectIrModeSize;
  options.streams.depth = false;
  return options;
}

TEST(FreenectIr, AnIrModeOfTheWrongSizeIsRefusedNamingTheDevice) {
  FreenectFeedOptions options = IrFeedOptions();
  options.streams.device = "Kinect 3";
  options.streams.video_size = cv::Size(320, 240);
  try {
    FreenectFrameFeed feed(options);
    FAIL() << "a 320x240 IR mode was accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("Kinect 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
  }
}

// Frames go through the real recorder into an IR-only recording: cropped to
// the depth image's 640x480 with the top rows kept, values as the device gave
// them, the device clock and the frame order kept.
TEST(FreenectIr, IrFramesAreRecordedCroppedToTheDepthImageWithTheirClock) {
  ScratchDir scratch;
  std::vector<cv::Mat> frames;
  std::vector<std::uint32_t> ticks;
  for (int i = 0; i < 3; ++i) {
    cv::Mat image(kKinectDepthSize, CV_8UC1);
    cv::randu(image, 0, 200);
    frames.push_back(image);
    ticks.push_back(4'294'000'000U + 2'000'000U * i);  // 30 Hz at 60 MHz, wrapping past 2^32
  }
  auto feed = std::make_unique<FreenectFrameFeed>(IrFeedOptions());
  std::thread device = PlayIrCallbacks(*feed, frames, ticks);
  SessionPlan plan;
  plan.streaming = true;
  plan.manifest.driver = "libfreenect";
  PlannedRecording ir{"ir_chessboard.h5", feed->Header(RecordingPurpose::kIrChessboard), std::move(feed)};
  plan.recordings.push_back(std::move(ir));
  const SessionRecordSummary summary = RecordSession(std::move(plan), scratch / "s");
  device.join();
  ASSERT_EQ(summary.recordings.size(), 1u);
  EXPECT_EQ(summary.recordings[0].frames, 3);

  const RecordingReader reader(scratch / "s" / "ir_chessboard.h5");
  EXPECT_EQ(reader.header().purpose, RecordingPurpose::kIrChessboard);
  EXPECT_EQ(reader.header().source, "freenect");
  EXPECT_EQ(reader.header().ir_size, std::optional(kKinectDepthSize));
  EXPECT_FALSE(reader.header().colour_size);
  EXPECT_FALSE(reader.header().depth_size);
  ASSERT_EQ(reader.frame_count(), 3);
  for (int i = 0; i < 3; ++i) {
    const FramePair pair = reader.ReadFrame(i);
    EXPECT_EQ(pair.source_number, i);
    EXPECT_EQ(pair.ir.device_timestamp, ticks[i]);
    EXPECT_GT(pair.ir.host_time_ns, 0);
    ASSERT_EQ(pair.ir.image.type(), CV_16UC1);
    cv::Mat expected;
    frames[i].convertTo(expected, CV_16U);
    EXPECT_EQ(cv::norm(pair.ir.image, expected, cv::NORM_INF), 0) << "frame " << i;
  }
}

// IR views of the board rendered by the simulator (10-bit) as the 8-bit frames
// a Kinect's IR mode gives, with their device clock.
void RenderIrViews(const sim::Scenario& scenario, std::vector<cv::Mat>* frames, std::vector<std::uint32_t>* ticks) {
  const sim::SessionSimulator simulator(scenario);
  for (const auto& spec : simulator.Frames(sim::SimRecording::kIrChessboard)) {
    cv::Mat ir8;
    simulator.Render(sim::SimRecording::kIrChessboard, spec).ir.convertTo(ir8, CV_8U, 0.25);
    frames->push_back(ir8);
    ticks->push_back(
        static_cast<std::uint32_t>(static_cast<std::uint64_t>(spec.context.time_s * 60e6) & 0xffffffffULL));
  }
}

TEST(FreenectIr, TheRecordedIrStepCalibratesTheDepthCamera) {
  ScratchDir scratch;
  sim::Scenario scenario;
  scenario.seed = 7;
  scenario.depthboard.poses = 12;
  scenario.depthboard.frames_per_pose = 1;
  scenario.planar.snapshots = 0;
  scenario.ir_chessboard.poses = 0;  // the simulator records no IR: the feed does
  sim::Scenario with_ir = scenario;
  with_ir.ir_chessboard.poses = 30;
  std::vector<cv::Mat> frames;
  std::vector<std::uint32_t> ticks;
  RenderIrViews(with_ir, &frames, &ticks);
  ASSERT_EQ(frames.size(), 30u);

  SessionPlan plan = PlanSimulatedSession(scenario, {});
  ASSERT_EQ(plan.recordings.size(), 1u) << "the simulated session should hold the depthboard only";
  auto feed = std::make_unique<FreenectFrameFeed>(IrFeedOptions());
  std::thread device = PlayIrCallbacks(*feed, frames, ticks);
  PlannedRecording ir{"ir_chessboard.h5", feed->Header(RecordingPurpose::kIrChessboard), std::move(feed)};
  plan.recordings.push_back(std::move(ir));
  RecordSession(std::move(plan), scratch / "s");
  device.join();

  const auto run = RunTool("run-pipeline", (scratch / "s").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json cameras = ReadJson(scratch / "s" / "calibrations" / "v0001" / "calibration.json")["cameras"];
  // The IR chessboards' camera, refined with the 12 depthboard outlines.
  EXPECT_EQ(cameras["depth_intrinsics_source"], "ir_chessboard+depth_outlines");
  const json& depth = cameras["depth"];
  EXPECT_EQ(depth["views"], 30 + 12) << depth;
  EXPECT_EQ(depth["image_size"], json({640, 480}));

  // The truth, as the session itself carries it: the scenario in the depthboard recording's header.
  const RecordingReader boards(scratch / "s" / "depthboard.h5");
  const sim::CameraModel truth =
      sim::OpticsFor(sim::ScenarioFromJson(json::parse(boards.header().scenario_json), "depthboard.h5")).ir;
  const double expected[] = {truth.fx, truth.fy, truth.cx, truth.cy};
  const char* names[] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    const double value = depth[names[i]].get<double>();
    const double sigma = depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"][i].get<double>();
    std::printf("IR %s: recovered %.2f (sigma %.2f), truth %.2f\n", names[i], value, sigma, expected[i]);
    // Within 4 sigma of the calibration's own uncertainty; focal lengths
    // within 1 %, the principal point within 3 px (keeping the wrong 8 rows
    // of the 488 would move cy by 8).
    EXPECT_LT(std::abs(value - expected[i]), std::max(4 * sigma, 0.5)) << names[i] << " = " << value;
    EXPECT_LT(std::abs(value - expected[i]), i < 2 ? 0.01 * expected[i] : 3.0) << names[i] << " = " << value;
  }
  EXPECT_LT(depth["rms_reprojection_px"].get<double>(), 0.5) << depth;
}

}  // namespace
}  // namespace speckle
