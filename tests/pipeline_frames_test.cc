// Frames the pipeline cannot use are skipped and explained, never fatal; and
// on wide-angle optics the undistortion flattens walls and the depth model
// lands on the truth.
#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "recorder/session_recorder.h"
#include "recorder/sources/sim_source.h"
#include "schemas/errors.h"
#include "simulator/scenario.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

// Spoils chosen frames of another source.
class SpoilingSource : public FrameSource {
 public:
  explicit SpoilingSource(std::unique_ptr<FrameSource> inner) : inner_(std::move(inner)) {}
  std::int64_t expected_frames() const override { return inner_->expected_frames(); }
  std::optional<FramePair> Next() override {
    auto frame = inner_->Next();
    if (!frame) return frame;
    switch (index_++) {
      case 2:  // no board in view: a blank wall
        frame->colour.image.setTo(cv::Scalar(200, 200, 200));
        frame->depth.image.setTo(cv::Scalar(990));
        break;
      case 4:  // the depth camera read nothing
        frame->depth.image.setTo(cv::Scalar(2047));
        break;
      case 6: {  // the board pushed half out of view
        const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 330, 0, 1, 0);
        cv::warpAffine(frame->colour.image, frame->colour.image, shift, frame->colour.image.size(), cv::INTER_NEAREST,
                       cv::BORDER_REPLICATE);
        cv::warpAffine(frame->depth.image, frame->depth.image, shift, frame->depth.image.size(), cv::INTER_NEAREST,
                       cv::BORDER_CONSTANT, cv::Scalar(2047));
        break;
      }
      case 8: {  // the depth image 10 px off its colour image (paired from another moment)
        const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 10, 0, 1, 0);
        cv::warpAffine(frame->depth.image, frame->depth.image, shift, frame->depth.image.size(), cv::INTER_NEAREST,
                       cv::BORDER_CONSTANT, cv::Scalar(2047));
        break;
      }
      default:
        break;
    }
    return frame;
  }

 private:
  std::unique_ptr<FrameSource> inner_;
  int index_ = 0;
};

// A board-only simulated session whose frames 2, 4, 6 and 8 SpoilingSource spoils.
void RecordSpoiledSession(const fs::path& out, int poses, int frames_per_pose) {
  sim::Scenario scenario;
  scenario.depthboard.poses = poses;
  scenario.depthboard.frames_per_pose = frames_per_pose;
  scenario.planar.snapshots = 0;
  scenario.ir_chessboard.poses = 12;
  SessionPlan plan = PlanSimulatedSession(scenario, {});
  plan.recordings.front().source = std::make_unique<SpoilingSource>(std::move(plan.recordings.front().source));
  RecordSession(std::move(plan), out);
}

TEST(PipelineFrames, UnusableFramesAreSkippedAndExplained) {
  ScratchDir s;
  RecordSpoiledSession(s / "x", 12, 1);

  const auto r = RunTool("run-pipeline", (s / "x").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rejected     4 frame(s)"), std::string::npos) << r.output;
  const json report = ReadJson(s / "x" / "calibrations" / "v0001" / "report.json");
  std::map<int, json> by_index;
  for (const auto& f : report["frames"])
    if (f["recording"] == "depthboard") by_index[f["index"].get<int>()] = f;
  EXPECT_EQ(by_index[2]["rejected_by"], "chessboard") << by_index[2];
  EXPECT_EQ(by_index[4]["rejected_by"], "depthboard_quad") << by_index[4];
  EXPECT_NE(by_index[4]["reason"].get<std::string>().find("too few valid depth pixels"), std::string::npos);
  EXPECT_TRUE(by_index[6].contains("rejected_by")) << by_index[6];
  // Its outline is found, 10 px from where the colour pose puts it: the
  // extrinsics leave it out, and its raw values are not paired with depths
  // from its colour pose.
  std::cerr << "frame 8: " << by_index[8]["reason"] << "\n";
  EXPECT_EQ(by_index[8]["rejected_by"], "extrinsics") << by_index[8];
  EXPECT_NE(by_index[8]["reason"].get<std::string>().find("px from where the colour pose"), std::string::npos)
      << by_index[8];
  for (int i : {0, 1, 3, 5, 7, 9, 10, 11}) EXPECT_GT(by_index[i]["samples"].get<int>(), 50) << "frame " << i;
}

// With still-board averaging, an all-invalid frame inside a still pose still
// gets the pose's outline, but pairing reads its own raw values and rejects it.
TEST(PipelineFrames, AveragedStillFramesFindOutlinesButPairEachFrameAlone) {
  ScratchDir s;
  RecordSpoiledSession(s / "x", 6, 3);

  const auto r = RunTool("run-pipeline", (s / "x").string() + " --average-still-frames 3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json report = ReadJson(s / "x" / "calibrations" / "v0001" / "report.json");
  EXPECT_EQ(report["depthboard_quads"]["still_frames_averaged"], 3);
  std::map<int, json> by_index;
  for (const auto& f : report["frames"])
    if (f["recording"] == "depthboard") by_index[f["index"].get<int>()] = f;
  EXPECT_TRUE(by_index[4].contains("quad_edge_rms_px"))
      << "the pose's other frames give frame 4 an outline: " << by_index[4];
  EXPECT_TRUE(by_index[4].contains("rejected_by")) << by_index[4];
  EXPECT_NE(by_index[4]["rejected_by"], "depthboard_quad") << by_index[4];
  for (int i : {0, 1, 3, 5, 9, 10, 11}) EXPECT_GT(by_index[i]["samples"].get<int>(), 50) << "frame " << i;
  const auto bad = RunTool("run-pipeline", (s / "x").string() + " --average-still-frames 0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("average-still-frames"), std::string::npos) << bad.output;
}

// Records examples/scenarios/<example>.json, patched, to `out`; returns run-pipeline's output.
std::string RecordAndCalibrate(const fs::path& out, const std::string& example, const json& patch) {
  json scenario = ReadJson(fs::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios" / (example + ".json"));
  scenario.merge_patch(patch);
  const fs::path file = out.string() + ".scenario.json";
  std::ofstream(file) << scenario.dump();
  const auto recorded = RunTool("record-session", "sim --scenario " + file.string() + " --out " + out.string());
  EXPECT_EQ(recorded.exit_code, 0) << recorded.output;
  const auto r = RunTool("run-pipeline", out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.output;
}

// A hand-held board sways while the depth image is exposed one frame after
// the colour image: its depth outline lags the colour pose, and the delay is
// fitted with the extrinsics instead of bending them into a rotation.
TEST(PipelineFrames, MovingBoardsDelayIsFittedWithTheExtrinsics) {
  ScratchDir s;
  RecordAndCalibrate(s / "m", "effect_capture_time_offset",
                     {{"depthboard", {{"poses", 30}}}, {"planar", {{"snapshots", 0}}}});
  const json extrinsics =
      ReadJson(s / "m" / "calibrations" / "v0001" / "calibration.json")["cameras"]["depth_from_colour"];
  ASSERT_TRUE(extrinsics["depth_delay_s"].is_number()) << extrinsics;
  EXPECT_NEAR(extrinsics["depth_delay_s"].get<double>(), 0.033, 0.005) << "the scenario's delay";
  EXPECT_LT(extrinsics["outline_rms_px"].get<double>(), 0.6) << extrinsics;
}

// Walls a degree or two from square to the sensor: each snapshot's measured
// tilt matches the simulator's truth, and the undistortion grid takes each
// wall's own plane as its truth instead of learning the tilts as distortion.
TEST(PipelineFrames, TiltedWallsAreMeasuredAndKeptOutOfTheUndistortionGrid) {
  ScratchDir s;
  const std::string output =
      RecordAndCalibrate(s / "t", "effect_misaligned_snapshots", {{"depthboard", {{"poses", 30}}}});
  EXPECT_NE(output.find("its own\n             tilted plane"), std::string::npos) << output;
  const json report = ReadJson(s / "t" / "calibrations" / "v0001" / "report.json");
  EXPECT_EQ(report["undistortion"]["true_raw_method"], "own_plane");
  EXPECT_GT(report["undistortion"]["wall_sigma_reduction_held_out"].get<double>(), -0.1) << "the grid may not hurt";
  // The truth: the angle between each wall's normal and the optical axis.
  H5::H5File planar((s / "t" / "planar.h5").string(), H5F_ACC_RDONLY);
  const H5::DataSet poses = planar.openDataSet("/truth/ir_from_target");
  hsize_t dims[3];
  poses.getSpace().getSimpleExtentDims(dims);
  std::vector<double> m(dims[0] * 16);
  poses.read(m.data(), H5::PredType::NATIVE_DOUBLE);
  int compared = 0;
  for (const auto& snapshot : report["planar_snapshots"]) {
    const std::size_t frame = snapshot["frame"];
    ASSERT_LT(frame, dims[0]);
    const double normal_z = m[frame * 16 + 2 * 4 + 2];  // row 2, column 2 of the 4 x 4 pose
    const double truth_deg = std::acos(std::min(1.0, std::abs(normal_z))) * 180 / M_PI;
    EXPECT_NEAR(snapshot["tilt_deg"].get<double>(), truth_deg, 0.15 + 0.1 * truth_deg) << "snapshot frame " << frame;
    ++compared;
  }
  EXPECT_GE(compared, 10);
}

TEST(PipelineFrames, WideAngleUndistortionFlattensWallsAndRecoversTheModel) {
  ScratchDir s;
  const auto recorded = RunTool(
      "record-session", "sim --scenario " +
                            (fs::path(SPECKLE_SOURCE_DIR) / "examples/scenarios/effect_radial_billow.json").string() +
                            " --out " + (s / "w").string());
  ASSERT_EQ(recorded.exit_code, 0) << recorded.output;
  const auto r = RunTool("run-pipeline", (s / "w").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json calibration = ReadJson(s / "w" / "calibrations" / "v0001" / "calibration.json");
  EXPECT_GE(calibration["metrics"]["wall_sigma_reduction"].get<double>(), 0.70) << "the thesis's figure";
  EXPECT_EQ(calibration["model"]["undistortion"], true);
  const double truth[] = {-0.0041952, 4.5380};  // the scenario's true reciprocal model
  for (int i = 0; i < 2; ++i) {
    const json& p = calibration["model"]["parameters"][i];
    EXPECT_LT(std::abs(p["value"].get<double>() - truth[i]), 3 * p["sigma"].get<double>()) << p;
  }
  const json report = ReadJson(s / "w" / "calibrations" / "v0001" / "report.json");
  const double without = FitHeldOutRaw(report, "reciprocal"), with = FitHeldOutRaw(report, "reciprocal +undistortion");
  ASSERT_GT(without, 0) << "no reciprocal fit in the report";
  ASSERT_GT(with, 0) << "no reciprocal +undistortion fit in the report";
  EXPECT_LT(with, 0.2 * without) << "undistortion must cut the held-out error";
}

}  // namespace
}  // namespace speckle
