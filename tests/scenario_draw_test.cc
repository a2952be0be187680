// Randomized scenarios: the draw is a function of the seed, stays within its
// stated spreads, rejects bad keys by path, and the drawn truth survives the
// trip through a recording's header.
#include <gtest/gtest.h>

#include <fstream>

#include "recorder/recording_reader.h"
#include "schemas/errors.h"
#include "simulator/scenario_draw.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle::sim {
namespace {

using testing::ReadJson;

nlohmann::json Example(const std::string& name) {
  return ReadJson(std::filesystem::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios" / name);
}

Scenario Drawn(nlohmann::json json, std::uint64_t seed) {
  json["seed"] = seed;
  return ScenarioFromJson(json, "test");
}

std::string MessageOf(const nlohmann::json& json) {
  try {
    ScenarioFromJson(json, "sc.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ScenarioDraw, SameSeedSameDraw) {
  EXPECT_EQ(ToJson(Drawn(Example("random_stock.json"), 4)), ToJson(Drawn(Example("random_stock.json"), 4)));
}

TEST(ScenarioDraw, DifferentSeedsDrawDifferentSensors) {
  const Scenario a = Drawn(Example("random_stock.json"), 1), b = Drawn(Example("random_stock.json"), 2);
  ASSERT_TRUE(a.ir_camera.intrinsics && b.ir_camera.intrinsics);
  EXPECT_NE(*a.ir_camera.intrinsics, *b.ir_camera.intrinsics);
  EXPECT_NE(*a.colour_camera.distortion, *b.colour_camera.distortion);
  EXPECT_NE(a.rig.background_behind_board_m, b.rig.background_behind_board_m);
}

TEST(ScenarioDraw, TheSessionStreamIsNotShiftedByTheDraw) {
  // The board poses come from the plain seed: a drawn scenario with the same
  // session and room as a plain one poses its boards identically.
  nlohmann::json plain = {{"depthboard", {{"poses", 3}, {"frames_per_pose", 1}}},
                          {"planar", {{"snapshots", 0}}},
                          {"ir_chessboard", {{"poses", 0}}}};
  nlohmann::json drawn = plain;
  drawn["randomize"] = {{"sensor",
                         {{"focal_fraction", 0},
                          {"principal_point_px", 0},
                          {"distortion_fraction", 0},
                          {"tangential_distortion", 0},
                          {"colour_from_ir_rotation_deg", 0},
                          {"colour_from_ir_translation_m", 0}}},
                        {"session", {{"poses", {3, 3}}, {"frames_per_pose", {1, 1}}, {"snapshots", {0, 0}}}}};
  const SessionSimulator a(ScenarioFromJson(plain, "plain")), b(ScenarioFromJson(drawn, "drawn"));
  const auto& fa = a.Frames(SimRecording::kDepthboard);
  const auto& fb = b.Frames(SimRecording::kDepthboard);
  ASSERT_EQ(fa.size(), 3u);
  ASSERT_EQ(fb.size(), 3u);
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_TRUE(fa[i].depth_target.ir_from_target.isApprox(fb[i].depth_target.ir_from_target, 1e-12)) << i;
  }
}

// Every drawn value over 200 seeds lies inside its spread, and the draws
// reach towards the spread's edges (a draw stuck at the preset fails too).
TEST(ScenarioDraw, DrawsStayWithinTheStatedSpreads) {
  const nlohmann::json json = Example("random_stock.json");
  const RandomizeSpec spec = RandomizeSpecFromJson(json["randomize"], "randomize");
  const SensorOptics preset = StockOptics();
  double widest_focal = 0, widest_cx = 0, widest_k2 = 0, widest_turn = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const Scenario s = Drawn(json, seed);
    const auto& ir = *s.ir_camera.intrinsics;
    const auto& k = *s.ir_camera.distortion;
    const double focal = ir[0] / preset.ir.fx - 1;
    EXPECT_LE(std::abs(focal), spec.sensor.focal_fraction + 1e-12);
    EXPECT_NEAR(ir[1] / preset.ir.fy - 1, focal, 1e-12) << "fx and fy scale together";
    EXPECT_LE(std::abs(ir[2] - preset.ir.cx), spec.sensor.principal_point_px);
    EXPECT_LE(std::abs(ir[3] - preset.ir.cy), spec.sensor.principal_point_px);
    EXPECT_LE(std::abs(k[1] / preset.ir.distortion[1] - 1), spec.sensor.distortion_fraction + 1e-12);
    EXPECT_LE(std::abs(k[2] - preset.ir.distortion[2]), spec.sensor.tangential_distortion + 1e-12);
    const double turn = Eigen::Vector3d::Map(s.colour_from_ir_rotation_deg->data()).norm();
    EXPECT_LE(turn, spec.sensor.colour_from_ir_rotation_deg + 1e-9);
    EXPECT_LE(std::abs((*s.colour_from_ir_m)[0] + 0.025), spec.sensor.colour_from_ir_translation_m + 1e-12);
    EXPECT_GE(s.rig.background_behind_board_m, 0.4);
    EXPECT_LE(s.rig.background_behind_board_m, 0.9);
    EXPECT_LE(std::hypot(s.rig.background_tilt_deg[0], s.rig.background_tilt_deg[1]), 20 + 1e-9);
    EXPECT_GE(s.room.floor_below_m, 0.6);
    EXPECT_LE(s.room.ceiling_above_m, 1.6);
    EXPECT_GE(s.depthboard.poses, 15);
    EXPECT_LE(s.depthboard.poses, 25);
    EXPECT_GE(s.depthboard.frames_per_pose, 1);
    EXPECT_LE(s.depthboard.frames_per_pose, 3);
    EXPECT_GE(s.planar.snapshots, 16);
    EXPECT_LE(s.planar.snapshots, 24);
    EXPECT_EQ(s.ir_chessboard.poses, 0) << "no IR recording in the random scenarios";
    EXPECT_EQ(s.effects["misaligned_snapshots"]["max_tilt_deg"], 2);
    widest_focal = std::max(widest_focal, std::abs(focal));
    widest_cx = std::max(widest_cx, std::abs(ir[2] - preset.ir.cx));
    widest_k2 = std::max(widest_k2, std::abs(k[1] / preset.ir.distortion[1] - 1));
    widest_turn = std::max(widest_turn, turn);
  }
  EXPECT_GT(widest_focal, 0.9 * spec.sensor.focal_fraction);
  EXPECT_GT(widest_cx, 0.9 * spec.sensor.principal_point_px);
  EXPECT_GT(widest_k2, 0.9 * spec.sensor.distortion_fraction);
  EXPECT_GT(widest_turn, 0.9 * spec.sensor.colour_from_ir_rotation_deg);
}

TEST(ScenarioDraw, BadKeysAreNamedByPath) {
  const auto names = [](const nlohmann::json& json, const std::string& path) {
    const std::string message = MessageOf(json);
    EXPECT_NE(message.find(path), std::string::npos) << message;
  };
  names({{"randomize", {{"sensor", {{"focal_fractoin", 0.01}}}}}},
        "sc.json.randomize.sensor: unknown key \"focal_fractoin\"");
  names({{"randomize", {{"sensor", {{"focal_fraction", 0.5}}}}}}, "sc.json.randomize.sensor.focal_fraction");
  names({{"randomize", {{"session", {{"poses", {25, 15}}}}}}}, "sc.json.randomize.session.poses");
  names({{"randomize", {{"scene", {{"floor_below_m", {0.5}}}}}}}, "sc.json.randomize.scene.floor_below_m");
  names({{"randomize", {{"weather", {}}}}}, "sc.json.randomize: unknown key \"weather\"");
  names({{"rig", {{"background_tilt_deg", {90, 0}}}}}, "sc.json.rig.background_tilt_deg");
}

TEST(ScenarioDraw, StoredScenarioReadsBackToTheDrawnValues) {
  const Scenario drawn = Drawn(Example("random_wide_angle.json"), 9);
  const nlohmann::json stored = ToJson(drawn);
  EXPECT_FALSE(stored.contains("randomize"));
  ASSERT_TRUE(stored.contains("drawn_from"));
  const Scenario again = ScenarioFromJson(stored, "stored");
  EXPECT_EQ(ToJson(again), stored);
  EXPECT_EQ(*again.ir_camera.intrinsics, *drawn.ir_camera.intrinsics);
  EXPECT_EQ(OpticsFor(again).colour_from_ir.matrix(), OpticsFor(drawn).colour_from_ir.matrix());
  nlohmann::json twice = stored;
  twice["randomize"] = nlohmann::json::object();
  EXPECT_NE(MessageOf(twice).find("sc.json.randomize: a scenario already drawn"), std::string::npos);
}

TEST(ScenarioDraw, RotationOverrideTurnsTheColourCamera) {
  const Scenario s = ScenarioFromJson({{"cameras", {{"colour_from_ir_rotation_deg", {0, 0.5, 0}}}}}, "test");
  const Eigen::AngleAxisd turn(OpticsFor(s).colour_from_ir.linear());
  EXPECT_NEAR(turn.angle(), 0.5 * M_PI / 180, 1e-12);
  EXPECT_NEAR(std::abs(turn.axis().y()), 1, 1e-12);
}

// The wall behind the board stands background_behind_board_m behind the
// board's centre: with no tilt, every background pixel reads that depth.
TEST(ScenarioDraw, BackgroundStandsBehindTheBoard) {
  const Scenario s = ScenarioFromJson({{"rig", {{"background_behind_board_m", 0.5}}},
                                       {"depthboard", {{"poses", 2}, {"frames_per_pose", 1}}},
                                       {"planar", {{"snapshots", 0}}},
                                       {"ir_chessboard", {{"poses", 0}}}},
                                      "test");
  const SessionSimulator sim(s);
  for (const auto& spec : sim.Frames(SimRecording::kDepthboard)) {
    const DepthTruth truth = sim.TrueDepth(spec);
    const Eigen::Vector3d centre =
        spec.depth_target.ir_from_target *
        Eigen::Vector3d(s.rig.squares_x * s.rig.square_size_m / 2, s.rig.squares_y * s.rig.square_size_m / 2, 0);
    int background = 0;
    for (int v = 0; v < truth.z_m.rows; ++v)
      for (int u = 0; u < truth.z_m.cols; ++u)
        if (truth.surface.at<std::uint8_t>(v, u) == static_cast<std::uint8_t>(Surface::kBackground)) {
          ++background;
          ASSERT_NEAR(truth.z_m.at<double>(v, u), centre.z() + 0.5, 1e-9);
        }
    EXPECT_GT(background, 100000);
  }
}

// Wide-angle optics see the room: floor, ceiling or furniture enter at least
// half of the far wall snapshots (the nearer half of the range is "near").
TEST(ScenarioDraw, RoomEntersHalfTheFarWideAngleSnapshots) {
  int far = 0, with_room = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SessionSimulator sim(Drawn(Example("random_wide_angle.json"), seed));
    const PlanarSpec& p = sim.scenario().planar;
    for (const auto& spec : sim.Frames(SimRecording::kPlanar)) {
      if (spec.context.seconds_into_pose > 0) continue;  // one frame per snapshot
      if (spec.depth_target.ir_from_target.translation().z() < (p.min_depth_m + p.max_depth_m) / 2) continue;
      const DepthTruth truth = sim.TrueDepth(spec);
      cv::Mat intruder =
          (truth.surface == static_cast<int>(Surface::kRoom)) | (truth.surface == static_cast<int>(Surface::kClutter));
      ++far;
      if (cv::countNonZero(intruder) > 0.01 * intruder.total()) ++with_room;
    }
  }
  ASSERT_GT(far, 20);
  EXPECT_GE(with_room, far / 2) << with_room << " of " << far;
}

// record-session --seed N draws session N from one file, and the drawn
// truth comes back from the recording's header.
TEST(ScenarioDraw, DrawnTruthRoundTripsThroughTheRecording) {
  testing::ScratchDir dir;
  nlohmann::json tiny = Example("random_stock.json");
  tiny["randomize"]["session"] = {{"poses", {2, 2}}, {"frames_per_pose", {1, 1}}, {"snapshots", {1, 1}}};
  std::ofstream(dir / "tiny.json") << tiny.dump();
  const auto recorded = testing::RunTool(
      "record-session", "sim --scenario " + (dir / "tiny.json").string() + " --seed 5 --out " + (dir / "s").string());
  ASSERT_EQ(recorded.exit_code, 0) << recorded.output;
  const RecordingReader reader(dir / "s" / "depthboard.h5");
  const nlohmann::json stored = nlohmann::json::parse(reader.header().scenario_json);
  EXPECT_EQ(stored["seed"], 5);
  EXPECT_EQ(stored, ToJson(Drawn(tiny, 5)));
  EXPECT_NE(stored["cameras"]["ir"], ToJson(Drawn(tiny, 1))["cameras"]["ir"]) << "--seed changed the draw";
}

}  // namespace
}  // namespace speckle::sim
