// The calibration graph itself, on a session made in memory: colour frames of
// a chessboard drawn through a known colour camera, depth frames of the same
// board proud of a wall drawn through a known depth camera, rig and
// reciprocal depth model, and one frame without a board. The graph must pair
// every board frame, reject the empty one at the chessboard, give each sample
// the raw value its true depth has, and give the same result however its
// threads and batches make frames finish.
#include <gtest/gtest.h>

#include <cmath>

#include <fstream>
#include <random>

#include "model/base_form.h"
#include "pipeline/calibration_graph.h"
#include "pipeline/cameras_json.h"
#include "schemas/errors.h"
#include "synthetic_views.h"

namespace speckle {
namespace {

const BoardGeometry kBoard{11, 8, 0.0223};
const CameraIntrinsics kColour = synthetic::Camera(529.2, 525.6, 322.4, 246.1);
const CameraIntrinsics kDepth = synthetic::Camera(588.9, 586.2, 316.8, 248.3);
const double kReciprocal[2] = {-0.0027681, 3.0163};  // the thesis's stock fit
constexpr double kWallM = 2.4;                       // the wall behind the board

Eigen::Isometry3d TrueDepthFromColour() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.004, Eigen::Vector3d(1, -1, 0).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(0.0252, 0.0008, -0.0012);
  return t;
}

double RawAt(double z_m) { return model::RawFromDepth(model::BaseForm::kReciprocal, kReciprocal, z_m); }

// The raw depth image: the board where a pixel's ray meets it, else the wall.
cv::Mat DrawRawDepth(const std::optional<Eigen::Isometry3d>& depth_from_board) {
  cv::Mat raw(kDepth.image_size, CV_16U);
  const cv::Matx33d& k = kDepth.camera_matrix;
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u) {
      const Eigen::Vector3d ray((u - k(0, 2)) / k(0, 0), (v - k(1, 2)) / k(1, 1), 1);
      double z = kWallM;
      if (depth_from_board) {
        const Eigen::Vector3d n = depth_from_board->linear().col(2);
        const double on_plane = n.dot(depth_from_board->translation()) / n.dot(ray);
        const Eigen::Vector3d p = depth_from_board->inverse() * (on_plane * ray);
        if (p.x() >= 0 && p.y() >= 0 && p.x() <= kBoard.Width() && p.y() <= kBoard.Height()) z = on_plane;
      }
      raw.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(std::lround(RawAt(z)));
    }
  return raw;
}

// A board pose whose outline is well inside both images.
bool InBothImages(const Eigen::Isometry3d& colour_from_board) {
  const cv::Rect inner(30, 30, 640 - 60, 480 - 60);
  for (const auto& corner : std::array<Eigen::Vector3d, 4>{Eigen::Vector3d(0, 0, 0),
                                                           {kBoard.Width(), 0, 0},
                                                           {kBoard.Width(), kBoard.Height(), 0},
                                                           {0, kBoard.Height(), 0}}) {
    const Eigen::Vector3d in_colour = colour_from_board * corner;
    if (!inner.contains(synthetic::ProjectPoint(kColour, in_colour)) ||
        !inner.contains(synthetic::ProjectPoint(kDepth, TrueDepthFromColour() * in_colour))) {
      return false;
    }
  }
  return true;
}

struct RecordedFrame {
  cv::Mat colour, raw;
};

// Eight board poses, then (frame 8) the wall alone.
std::vector<RecordedFrame> Record() {
  std::mt19937 rng(51);
  std::vector<RecordedFrame> frames;
  while (frames.size() < 8) {
    const auto pose = synthetic::SpreadPoses(kBoard, 1, rng, 0.7, 1.3).front();
    if (!InBothImages(pose)) continue;
    cv::Mat colour;
    cv::cvtColor(synthetic::RenderChessboard(kColour, kBoard, pose, 2.0, rng), colour, cv::COLOR_GRAY2RGB);
    frames.push_back({colour, DrawRawDepth(TrueDepthFromColour() * pose)});
  }
  frames.push_back({cv::Mat(kColour.image_size, CV_8UC3, cv::Scalar(128, 128, 128)), DrawRawDepth(std::nullopt)});
  return frames;
}

KnownIntrinsics Known(const CameraIntrinsics& c) {
  const cv::Matx33d& k = c.camera_matrix;
  return {c.image_size.width, c.image_size.height, k(0, 0), k(1, 1), k(0, 2), k(1, 2), {}};
}

// The session as the graph reads it: fresh frames every run (the graph
// writes into them), one a second.
GraphInput Session(const std::vector<RecordedFrame>& recorded) {
  GraphInput in;
  in.session_dir = "in-memory";
  in.manifest.rig =
      RigInfo{kBoard.squares_x, kBoard.squares_y, kBoard.square_size_m, BoardOutline::kChessboardEdge, ""};
  in.manifest.colour_intrinsics = Known(kColour);
  in.manifest.depth_intrinsics = Known(kDepth);
  in.depth_size = kDepth.image_size;
  in.boards.frames = static_cast<std::int64_t>(recorded.size());
  in.boards.next = [&recorded, next = std::size_t{0}]() mutable -> Frame {
    if (next >= recorded.size()) return nullptr;
    auto f = std::make_shared<FrameWork>();
    f->index = static_cast<int>(next);
    f->source_number = f->index;
    f->time_s = f->index;
    f->colour = recorded[next].colour.clone();
    f->raw = RawDepth(recorded[next].raw.clone(), nullptr, f->index);
    ++next;
    return f;
  };
  return in;
}

PipelineResult RunGraph(const std::vector<RecordedFrame>& recorded, int threads, int batch_frames) {
  PipelineOptions options;
  options.threads = threads;
  options.batch_frames = batch_frames;
  return RunCalibrationGraph(Session(recorded), options);
}

const std::vector<RecordedFrame>& Recorded() {
  static const std::vector<RecordedFrame> recorded = Record();
  return recorded;
}

// run-pipeline's options check themselves before the graph is built.
TEST(PipelineOptions, DefaultsAreValidAndABrokenRuleIsNamed) {
  std::string why;
  EXPECT_TRUE(PipelineOptions{}.IsValid(&why)) << why;
  PipelineOptions options;
  options.batch_frames = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("batch_frames"), std::string::npos) << why;
  options = {};
  options.still_frames_averaged = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("still_frames_averaged"), std::string::npos) << why;
}

// Every stage's options are checked with the run's, each named by its path.
TEST(PipelineOptions, AStageRuleBrokenIsNamedByItsPath) {
  std::string why;
  PipelineOptions options;
  options.planar.segmentation.stride = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "planar.segmentation.stride must be finite and >= 1");
  options = {};
  options.extrinsics.outlier_px = std::nan("");
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "extrinsics.outlier_px must be finite and > 0");
  options = {};
  options.still_average.min_valid_share = 1.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "still_average.min_valid_share must be a share from 0 to 1");
  options = {};
  options.intrinsics.max_views = options.intrinsics.min_views - 1;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "intrinsics.max_views must be >= min_views");
  options = {};
  options.joint.hold_out_function_tolerance = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "joint.hold_out_function_tolerance must be in (0, 1)");
}

TEST(CalibrationGraph, PairsEveryBoardFrameAndRejectsTheEmptyOne) {
  const PipelineResult result = RunGraph(Recorded(), 2, 4);
  ASSERT_EQ(result.frames.size(), 9u);
  for (const FrameOutcome& f : result.frames) {
    SCOPED_TRACE("frame " + std::to_string(f.index));
    if (f.index < 8) {
      EXPECT_FALSE(f.rejection.has_value()) << f.rejection->stage << ": " << f.rejection->reason;
      EXPECT_GT(f.samples, 100);  // 70 corners and 88 square centres, a few lost near the edge
    } else {
      ASSERT_TRUE(f.rejection.has_value());
      EXPECT_EQ(f.rejection->stage, "chessboard");
      EXPECT_EQ(f.samples, 0);
    }
  }
  EXPECT_EQ(result.paired_frames, 8);
}

TEST(CalibrationGraph, EachSampleHasTheRawValueOfItsTrueDepth) {
  // The graph's whole chain (detection, colour pose, outline, extrinsics,
  // depth pose, pairing) must put each sample where the drawn raw value
  // belongs to its depth. Raw values are drawn in whole steps, and pairing
  // fits a plane through 25 of them, so rounding leaves about 0.1 step;
  // measured over 1264 samples: RMS 0.088, worst 0.27 steps, the rig 0.11 mm
  // off. Bounds: RMS 0.25, worst 0.75 steps (one step is 2.8 mm at 1 m), the
  // rig within 1 mm (the nominal rig it starts from is 2 mm and 0.3 degrees off).
  const PipelineResult result = RunGraph(Recorded(), 2, 4);
  ASSERT_GT(result.samples.size(), 800u);
  double squares = 0, worst = 0;
  for (const PairedSample& s : result.samples) {
    const double error = s.raw - RawAt(s.depth_m);
    squares += error * error, worst = std::max(worst, std::abs(error));
  }
  EXPECT_LT(std::sqrt(squares / static_cast<double>(result.samples.size())), 0.25);
  EXPECT_LT(worst, 0.75);
  EXPECT_LT((result.cameras.depth_from_colour.translation() - TrueDepthFromColour().translation()).norm(), 0.001);
}

TEST(CalibrationGraph, ResultDoesNotDependOnTheOrderFramesFinish) {
  // One thread and one frame a batch finish frames in recording order; two
  // threads and batches of 4 and 3 finish them as they come. The barriers
  // must hand the same frames on in the same order, so the samples are
  // identical to the last bit.
  const PipelineResult serial = RunGraph(Recorded(), 1, 1);
  for (const auto& [threads, batch] : std::vector<std::pair<int, int>>{{2, 4}, {2, 3}, {4, 1}}) {
    SCOPED_TRACE(std::to_string(threads) + " threads, batches of " + std::to_string(batch));
    const PipelineResult parallel = RunGraph(Recorded(), threads, batch);
    ASSERT_EQ(parallel.samples.size(), serial.samples.size());
    for (std::size_t i = 0; i < serial.samples.size(); ++i) {
      const PairedSample &a = serial.samples[i], &b = parallel.samples[i];
      ASSERT_EQ(a.frame, b.frame) << "sample " << i;
      ASSERT_EQ(a.u, b.u) << "sample " << i;
      ASSERT_EQ(a.v, b.v) << "sample " << i;
      ASSERT_EQ(a.raw, b.raw) << "sample " << i;
      ASSERT_EQ(a.depth_m, b.depth_m) << "sample " << i;
    }
    EXPECT_TRUE(parallel.cameras.depth_from_colour.isApprox(serial.cameras.depth_from_colour, 0));
  }
}

}  // namespace
}  // namespace speckle

namespace speckle {
namespace {

// calibration.json's cameras read back, as a refit starts from them: the
// views each camera came from are read where the file has them (a refit's
// loose-camera warning said "0 views"), and a value that is not a count of
// views reads as none rather than a wrapped or negative count; a missing
// focal length is still refused naming its field.
TEST(CamerasJson, ViewsAreReadBackAndAnImpossibleCountReadsAsNone) {
  std::ifstream in(std::string(SPECKLE_SOURCE_DIR) + "/tests/golden/expected_calibration.json");
  nlohmann::json cameras = nlohmann::json::parse(in)["cameras"];
  EXPECT_EQ(CamerasFromJson(cameras, "cameras").depth.views, 18);
  EXPECT_EQ(CamerasFromJson(cameras, "cameras").colour.views, 10);
  for (const nlohmann::json& odd : {nlohmann::json("many"), nlohmann::json(-3), nlohmann::json(1e12),
                                    nlohmann::json(4.5), nlohmann::json(nullptr)}) {
    cameras["depth"]["views"] = odd;
    EXPECT_EQ(CamerasFromJson(cameras, "cameras").depth.views, 0) << odd.dump();
  }
  cameras["depth"].erase("views");
  EXPECT_EQ(CamerasFromJson(cameras, "cameras").depth.views, 0);
  cameras["depth"].erase("fx");
  try {
    CamerasFromJson(cameras, "cameras");
    ADD_FAILURE() << "a depth camera without fx was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.depth"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace speckle
