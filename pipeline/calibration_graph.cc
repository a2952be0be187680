// The calibration flow graph, wired in one place:
//
//   read ir ──── detect (IR) ──────────────┐
//   read boards ─ detect or track (colour) ┼─ split ─ calibrate cameras ─ extract quad ─ fit extrinsics ─┬─ pose + pair ─ collect
//   read planar ───────────────────────────┘          (barrier)          (or board region) (barrier)     └─ clean snapshot ─ collect
//
// Boards larger than their chessboard have no outline at the chessboard's
// edge: "extract quad" then finds the board region, and "fit extrinsics"
// estimates depth intrinsics, extrinsics and depth model jointly from the
// board planes (Herrera et al.), which also yields the paired samples.
//
// With still_frames_averaged > 1, "extract quad" finds each outline in the
// median of the frames around it of the same still pose (the thesis averaged
// depth images by hand for this); pairing still reads each frame's own raw.
//
// Readers emit small batches of consecutive frames (board frames of a still
// pose track the board from one frame to the next inside a batch).
//
// then, once the graph is drained: build the undistortion grid. Readers are
// serial (one HDF5 reader each); per-frame stages run in parallel. A frame
// that fails a stage carries a Rejection on to the collectors; no exception
// leaves a node.
#include "pipeline/calibration_graph.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/flow_graph.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for_each.h>
#include <tbb/parallel_invoke.h>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>

#include "recorder/progress.h"
#include "recorder/recording_clock.h"
#include "recorder/recording_reader.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"
#include "pipeline/depth_camera_step.h"
#include "stages/camera_calibration.h"
#include "stages/rate_neighbours.h"

namespace speckle {
namespace {

namespace flow = tbb::flow;

enum class Kind { kIr, kBoard, kPlanar };

// One frame on its way through the graph.
struct FrameWork {
  Kind kind = Kind::kBoard;
  int index = 0;
  std::int64_t source_number = -1;
  double time_s = 0;
  cv::Mat colour, raw, ir;
  std::optional<ChessboardDetection> detection;
  Eigen::Isometry3d colour_from_board = Eigen::Isometry3d::Identity();
  PoseCovariance colour_pose_covariance = PoseCovariance::Zero();
  std::vector<cv::Mat> still_neighbours;  // raw frames of the same still pose, for quad averaging
  std::optional<DepthboardQuad> quad;
  std::optional<BoardRegion> region;
  std::vector<PairedSample> samples;
  std::optional<PlanarSnapshot> snapshot;
  std::optional<Rejection> rejection;
  int pose = -1;
  double motion_px = 0;
  Eigen::Vector2d velocity_px_s = Eigen::Vector2d::Zero();
  // The board centre's velocity in the colour camera (m/s). Only the centre:
  // a pose's rotation about its centre is its least certain part, and the
  // difference of two poses 33 ms apart would turn its scatter into motion
  // (1 degree between a detected and a tracked frame reads as 0.1 m/s at the
  // board's edge).
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();
};
using Frame = std::shared_ptr<FrameWork>;
using Batch = std::vector<Frame>;

enum StageId { kRead, kDetect, kTrack, kCalibrate, kQuad, kExtrinsics, kPosePair, kPlanarClean, kGrid, kStageCount };
constexpr const char* kStageNames[kStageCount] = {"read",        "chessboard_detection", "chessboard_tracking",
                                                  "camera_calibration",
                                                  "depthboard_quad", "extrinsics", "depth_pose_and_pairing",
                                                  "planar_cleanup",  "undistortion_grid"};

class StageClocks {
 public:
  template <typename F>
  auto Time(StageId stage, F&& body) {
    const auto start = std::chrono::steady_clock::now();
    struct Stop {
      StageClocks* self;
      StageId stage;
      std::chrono::steady_clock::time_point start;
      ~Stop() {
        self->ns_[stage] += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
        ++self->calls_[stage];
      }
    } stop{this, stage, start};
    return body();
  }
  std::vector<StageTiming> Timings() const {
    std::vector<StageTiming> out;
    for (int s = 0; s < kStageCount; ++s) out.push_back({kStageNames[s], ns_[s] * 1e-9, calls_[s].load()});
    return out;
  }

 private:
  std::array<std::atomic<std::int64_t>, kStageCount> ns_{};
  std::array<std::atomic<int>, kStageCount> calls_{};
};

// Runs a stage body; an escaping exception becomes the frame's rejection.
template <typename F>
void Guarded(FrameWork& f, const char* stage, F&& body) {
  if (f.rejection) return;
  try {
    body();
  } catch (const std::exception& e) {
    f.rejection = Rejection{stage, std::string("failed: ") + e.what()};
  }
}

template <typename T>
void Take(FrameWork& f, StageResult<T> result, std::optional<T>* into) {
  if (Accepted(result)) {
    *into = std::move(std::get<T>(result));
  } else {
    f.rejection = std::get<Rejection>(result);
  }
}

const RecordingEntry* FindRecording(const SessionManifest& m, RecordingPurpose purpose) {
  for (const auto& r : m.recordings)
    if (r.purpose == purpose) return &r;
  return nullptr;
}

// Reads one recording's frames in order, for an input_node.
class FrameFeed {
 public:
  FrameFeed(const std::filesystem::path& path, Kind kind) : reader_(path), kind_(kind) {}
  std::int64_t count() const { return reader_.frame_count(); }
  Frame Next() {
    if (next_ >= reader_.frame_count()) return nullptr;
    auto f = std::make_shared<FrameWork>();
    f->kind = kind_;
    f->index = static_cast<int>(next_);
    FramePair pair = reader_.ReadFrame(next_++);
    f->source_number = pair.source_number;
    f->colour = pair.colour.image;
    f->raw = pair.depth.image;
    f->ir = pair.ir.image;
    f->time_s = clock_.Seconds(pair);
    return f;
  }
  const RecordingReader& reader() const { return reader_; }

 private:
  RecordingReader reader_;
  Kind kind_;
  std::int64_t next_ = 0;
  RecordingClock clock_;
};

// The Kinect's nominal depth camera (ROS defaults) for sessions without IR
// chessboard frames.
CameraIntrinsics FromSession(const KnownIntrinsics& k) {
  CameraIntrinsics c;
  c.image_size = cv::Size(k.width, k.height);
  c.camera_matrix = cv::Matx33d(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  c.distortion = k.distortion;
  return c;
}

CameraIntrinsics NominalDepthCamera(cv::Size size) {
  CameraIntrinsics c;
  c.image_size = size;
  c.camera_matrix = cv::Matx33d(580, 0, (size.width - 1) / 2.0, 0, 580, (size.height - 1) / 2.0, 0, 0, 1);
  return c;
}

// Groups consecutive frames of a still board and measures corner motion.
// The image velocity comes from any two consecutive frames of a board, still
// or not: a hand-held board drifting a few pixels a frame splits into
// one-frame poses, yet its velocity is what a capture-time offset needs.
void AssignPoses(std::vector<Frame>& boards, double still_motion_px, double max_velocity_gap_s) {
  std::sort(boards.begin(), boards.end(), [](const Frame& a, const Frame& b) { return a->index < b->index; });
  int pose = -1;
  FrameWork* previous = nullptr;
  for (Frame& f : boards) {
    if (!f->detection) {
      previous = nullptr;
      continue;
    }
    double motion = 1e9;
    Eigen::Vector2d shift = Eigen::Vector2d::Zero();
    if (previous) {
      motion = 0;
      for (std::size_t k = 0; k < f->detection->corners.size(); ++k) {
        const cv::Point2f d = f->detection->corners[k] - previous->detection->corners[k];
        motion += cv::norm(d);
        shift += Eigen::Vector2d(d.x, d.y);
      }
      motion /= static_cast<double>(f->detection->corners.size());
      shift /= static_cast<double>(f->detection->corners.size());
    }
    const bool same_pose = motion <= still_motion_px;
    if (!same_pose) ++pose;
    f->pose = pose;
    f->motion_px = motion > 1e8 ? 0 : motion;
    const double dt = previous ? f->time_s - previous->time_s : 0;
    if (dt > 0 && dt <= max_velocity_gap_s) {
      f->velocity_px_s = shift / dt;
      // A first frame has no predecessor: it drifts as its successor.
      if (previous->velocity_px_s.isZero()) previous->velocity_px_s = f->velocity_px_s;
    }
    previous = &*f;
  }
}

// Each board frame's velocity from the colour poses of two other frames of
// its run (see RateNeighbours), boards in recording order.
void AssignBoardMotion(std::vector<Frame>& boards, const Eigen::Vector3d& centre_in_board, double max_gap_s) {
  std::vector<double> times;
  std::vector<bool> usable;
  for (const Frame& b : boards) times.push_back(b->time_s), usable.push_back(b->detection && !b->rejection);
  for (std::size_t i = 0; i < boards.size(); ++i) {
    const auto pair = usable[i] ? RateNeighbours(times, usable, i, max_gap_s) : std::nullopt;
    if (!pair) continue;
    const FrameWork &a = *boards[pair->first], &b = *boards[pair->second];
    boards[i]->board_velocity =
        (b.colour_from_board * centre_in_board - a.colour_from_board * centre_in_board) / (b.time_s - a.time_s);
  }
}

// Gives each board frame the raw frames of up to `window` consecutive frames
// of its still pose, centred on it, for the quad to be found in their median.
void GatherStillNeighbours(std::vector<Frame>& boards, int window) {
  if (window <= 1) return;
  for (std::size_t i = 0; i < boards.size(); ++i) {
    FrameWork& f = *boards[i];
    if (f.pose < 0 || !f.detection) continue;
    const auto same_pose = [&](std::size_t k) { return boards[k]->pose == f.pose && boards[k]->detection && !boards[k]->raw.empty(); };
    std::size_t first = i, last = i;  // inclusive
    while (static_cast<int>(last - first + 1) < window) {
      const bool before = first > 0 && same_pose(first - 1), after = last + 1 < boards.size() && same_pose(last + 1);
      if (!before && !after) break;
      // Alternate sides so the window stays centred where it can.
      if (after && (!before || last - i <= i - first)) ++last;
      else --first;
    }
    for (std::size_t k = first; k <= last; ++k) f.still_neighbours.push_back(boards[k]->raw);
  }
}

}  // namespace

PipelineOptions ForDepthUnits(PipelineOptions options, DepthUnits units) {
  const DepthReading reading(units);
  options.quad.reading = options.still_average.reading = options.board_region.reading = reading;
  options.pairing.reading = options.planar.reading = options.extrinsics.reading = reading;
  if (units == DepthUnits::kMillimetre) options.joint_plane.form = model::BaseForm::kLinearMm;
  return options;
}

PipelineResult RunCalibrationGraph(const std::filesystem::path& session_dir, const PipelineOptions& requested) {
  const auto wall_start = std::chrono::steady_clock::now();
  const SessionManifest manifest = ReadSessionManifest(session_dir);
  const PipelineOptions options = ForDepthUnits(requested, manifest.depth_units);
  if (!manifest.rig) {
    throw InputError((session_dir / kSessionFileName).string() +
                     ": no rig described; the pipeline needs the board's squares and square size");
  }
  const BoardGeometry board{manifest.rig->squares_x, manifest.rig->squares_y, manifest.rig->square_size_m};
  const RecordingEntry* boards_entry = FindRecording(manifest, RecordingPurpose::kDepthboard);
  if (!boards_entry) throw InputError(session_dir.string() + ": the session has no depthboard recording to calibrate from");
  const RecordingEntry* planar_entry = FindRecording(manifest, RecordingPurpose::kPlanar);
  const RecordingEntry* ir_entry = FindRecording(manifest, RecordingPurpose::kIrChessboard);

  std::optional<tbb::global_control> thread_limit;
  if (options.threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, options.threads);

  FrameFeed board_feed(session_dir / boards_entry->file, Kind::kBoard);
  std::optional<FrameFeed> planar_feed, ir_feed;
  if (planar_entry) planar_feed.emplace(session_dir / planar_entry->file, Kind::kPlanar);
  if (ir_entry) ir_feed.emplace(session_dir / ir_entry->file, Kind::kIr);
  if (!board_feed.reader().header().colour_size || !board_feed.reader().header().depth_size) {
    throw InputError(board_feed.reader().path().string() + ": a depthboard recording needs colour and depth frames");
  }
  const cv::Size depth_size = *board_feed.reader().header().depth_size;

  PipelineResult result;
  result.board = board;
  result.depth_units = manifest.depth_units;
  result.still_frames_averaged = std::max(1, options.still_frames_averaged);
  StageClocks clocks;
  std::mutex outcome_mutex;
  std::vector<Frame> finished;
  const auto finish = [&](const Frame& f) {
    std::lock_guard lock(outcome_mutex);
    finished.push_back(f);
  };
  const std::int64_t total = board_feed.count() + (planar_feed ? planar_feed->count() : 0) +
                             (ir_feed ? ir_feed->count() : 0);
  Progress progress("run-pipeline", total);
  std::atomic<std::int64_t> done{0};

  flow::graph g;
  // A reader for an input_node; `feed` is null for a recording the session lacks.
  const auto reader = [&](FrameFeed* feed, int batch_frames) {
    return [&clocks, feed, batch_frames](tbb::flow_control& control) -> Batch {
      Batch batch;
      while (feed && static_cast<int>(batch.size()) < batch_frames) {
        Frame frame = clocks.Time(kRead, [&] { return feed->Next(); });
        if (!frame) break;
        batch.push_back(std::move(frame));
      }
      if (batch.empty()) control.stop();
      return batch;
    };
  };
  flow::input_node<Batch> read_boards(g, reader(&board_feed, std::max(1, options.batch_frames)));
  flow::input_node<Batch> read_planar(g, reader(planar_feed ? &*planar_feed : nullptr, 1));
  flow::input_node<Batch> read_ir(g, reader(ir_feed ? &*ir_feed : nullptr, 1));

  flow::function_node<Batch, Batch> detect(g, flow::unlimited, [&](Batch batch) {
    const ChessboardDetection* previous = nullptr;
    for (const Frame& f : batch) {
      Guarded(*f, "chessboard", [&] {
        if (f->kind == Kind::kPlanar) return;
        const cv::Mat& image = f->kind == Kind::kIr ? f->ir : f->colour;
        if (previous) {
          auto tracked = clocks.Time(kTrack, [&] { return RunChessboardTracking(options.tracking, board, image, *previous); });
          if (Accepted(tracked)) f->detection = std::move(std::get<ChessboardDetection>(tracked));
        }
        if (!f->detection) {
          Take(*f, clocks.Time(kDetect, [&] { return RunChessboardDetection(options.detection, board, image); }),
               &f->detection);
        }
        f->colour.release();  // only detections are needed from here on
        f->ir.release();
      });
      previous = f->detection ? &*f->detection : nullptr;
    }
    return batch;
  });

  using Split = flow::multifunction_node<Batch, std::tuple<Frame>>;
  Split split(g, flow::unlimited, [](const Batch& batch, Split::output_ports_type& out) {
    for (const Frame& f : batch) std::get<0>(out).try_put(f);
  });

  const bool plane_mode = manifest.rig->outline != BoardOutline::kChessboardEdge;
  // Without depth intrinsics from the session or IR images, the depth camera
  // comes from the outlines (pipeline/depth_camera_step.h): the first outlines
  // are found with gates widened by how far the nominal camera may be off.
  bool depth_camera_from_outlines = false;
  std::optional<std::string> depth_camera_failure;  // why the outlines could not give the depth camera
  // Barrier: every detection in, then the cameras are calibrated once; board
  // and planar frames go on (planar ones wait for the final depth intrinsics).
  using Release = flow::multifunction_node<Frame, std::tuple<Frame>>;
  std::vector<Frame> held;
  const auto calibrate_cameras = [&] {
    std::vector<Frame> boards;
    std::vector<ChessboardDetection> ir_views;
    // Frames arrive in whatever order the graph finished them: calibrate
    // from them in recording order, so that a run is reproducible.
    std::sort(held.begin(), held.end(), [](const Frame& a, const Frame& b) { return a->index < b->index; });
    for (const Frame& h : held) {
      if (h->kind == Kind::kBoard) boards.push_back(h);
      if (h->kind == Kind::kIr && h->detection) ir_views.push_back(*h->detection);
    }
    AssignPoses(boards, options.still_pose_motion_px, options.max_velocity_gap_s);
    GatherStillNeighbours(boards, options.still_frames_averaged);
    // One view per still pose calibrates the colour camera.
    std::vector<ChessboardDetection> pose_views;
    int last_pose = -1;
    for (const Frame& b : boards) {
      if (b->detection && b->pose != last_pose) pose_views.push_back(*b->detection);
      if (b->detection) last_pose = b->pose;
    }
    // Colour and IR intrinsics are independent: calibrate them side by side.
    std::optional<std::string> colour_failure;
    tbb::parallel_invoke(
        [&] {
          if (manifest.colour_intrinsics) {
            result.cameras.colour = FromSession(*manifest.colour_intrinsics);
            return;
          }
          try {
            result.cameras.colour = RunIntrinsicsCalibration(options.intrinsics, board, pose_views);
          } catch (const InputError& e) {
            colour_failure = e.what();
          }
        },
        [&] {
          if (manifest.depth_intrinsics) {
            result.cameras.depth = FromSession(*manifest.depth_intrinsics);
            result.cameras.depth_intrinsics_source = "session";
          } else if (ir_views.size() >= static_cast<std::size_t>(options.intrinsics.min_views)) {
            result.cameras.depth = RunIntrinsicsCalibration(options.intrinsics, board, ir_views);
            result.cameras.depth_intrinsics_source = "ir_chessboard";
          } else {
            result.cameras.depth = NominalDepthCamera(depth_size);
            result.cameras.depth_intrinsics_source = "nominal";
            depth_camera_from_outlines = !plane_mode;
          }
        });
    if (colour_failure) {
      for (const Frame& b : boards)
        if (!b->rejection) b->rejection = Rejection{"camera_calibration", *colour_failure};
      return;
    }
    const auto describe = [](const CameraIntrinsics& c) {
      return fmt::format("fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f} k {:.3f} {:.3f} {:.4f} {:.4f} {:.3f}, rms {:.3f} px over {} views",
                         c.camera_matrix(0, 0), c.camera_matrix(1, 1), c.camera_matrix(0, 2), c.camera_matrix(1, 2),
                         c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3], c.distortion[4],
                         c.rms_reprojection_px, c.views);
    };
    spdlog::info("colour camera: {}", describe(result.cameras.colour));
    spdlog::info("depth camera ({}): {}", result.cameras.depth_intrinsics_source, describe(result.cameras.depth));
    // Nominal extrinsics until the quads refine them: the colour camera sits
    // about 2.5 cm beside the IR camera.
    result.cameras.depth_from_colour = Eigen::Isometry3d::Identity();
    result.cameras.depth_from_colour.translation() = Eigen::Vector3d(0.025, 0, 0);
    tbb::parallel_for_each(boards.begin(), boards.end(), [&](const Frame& b) {
      Guarded(*b, "camera_calibration", [&] {
        b->colour_from_board = BoardPose(result.cameras.colour, board, *b->detection);
        b->colour_pose_covariance = BoardPoseCovariance(result.cameras.colour, board, *b->detection, b->colour_from_board);
      });
    });
    AssignBoardMotion(boards, Eigen::Vector3d(board.Width() / 2, board.Height() / 2, 0), options.max_velocity_gap_s);
  };
  Release calibrate(g, flow::serial, [&](Frame f, Release::output_ports_type& out) {
    held.push_back(f);
    if (static_cast<std::int64_t>(held.size()) < total) return;
    clocks.Time(kCalibrate, calibrate_cameras);
    for (const Frame& h : held) {
      if (h->kind == Kind::kIr) {
        finish(h);
        progress.Update(++done);
      } else {
        std::get<0>(out).try_put(h);
      }
    }
    held.clear();
  });

  const auto outline = OutlineCorners(board);
  flow::function_node<Frame, Frame> extract_quad(g, flow::unlimited, [&](Frame f) {
    if (f->kind != Kind::kBoard) return f;
    Guarded(*f, plane_mode ? "board_region" : "depthboard_quad", [&] {
      std::array<Eigen::Vector2d, 4> predicted;
      for (int k = 0; k < 4; ++k) {
        predicted[k] = result.cameras.depth.Project(result.cameras.depth_from_colour * f->colour_from_board * outline[k]);
      }
      if (plane_mode) {
        const double square_px = (predicted[1] - predicted[0]).norm() / board.squares_x;
        Take(*f, clocks.Time(kQuad, [&] { return RunBoardRegion(options.board_region, f->raw, predicted, square_px); }),
             &f->region);
      } else {
        const double uncertainty = depth_camera_from_outlines ? options.nominal_prediction_px : 0;
        Take(*f, clocks.Time(kQuad, [&] {
          return FindOutline(options.quad, options.still_average, f->still_neighbours, f->raw, predicted, uncertainty);
        }), &f->quad);
      }
    });
    if (!depth_camera_from_outlines) f->still_neighbours.clear();  // the fine outlines need them again
    return f;
  });

  // Barrier: every quad (or board region) in, then the extrinsics are fitted
  // once; board frames go on to pairing (port 0), planar ones to cleanup (port 1).
  using Pass = flow::multifunction_node<Frame, std::tuple<Frame, Frame>>;
  std::vector<Frame> quads;
  const std::int64_t second_barrier = board_feed.count() + (planar_feed ? planar_feed->count() : 0);
  const auto fit_planes = [&] {
    std::vector<PlaneObservation> observations;
    std::vector<Frame> observed;
    for (const Frame& q : quads) {
      if (q->kind != Kind::kBoard || q->rejection || !q->region) continue;
      observations.push_back({q->index, q->pose, q->time_s, q->colour_from_board, *q->region});
      observed.push_back(q);
    }
    auto joint = RunJointPlaneCalibration(options.joint_plane, observations, result.cameras.depth,
                                                result.cameras.depth_from_colour);
    if (!Accepted(joint)) {
      for (const Frame& q : observed) q->rejection = std::get<Rejection>(joint);
      return;
    }
    auto& j = std::get<JointPlaneResult>(joint);
    AddJointPlaneUncertainty(options.joint_plane, observations, j);
    j.depth.views = static_cast<int>(observations.size());
    if (auto loose = LooselyPinned(options.extrinsics, j.depth, "the board planes")) {
      result.cameras.depth_intrinsics_warning = *loose;
      spdlog::warn("{}", *loose);
    }
    result.cameras.depth = j.depth;
    result.cameras.depth_intrinsics_source = "joint_board_planes";
    result.cameras.depth_from_colour = j.depth_from_colour;
    result.cameras.extrinsics_views = static_cast<int>(observations.size());
    result.cameras.extrinsics_rms_px = 0;
    spdlog::info("board planes: {} pixels from {} poses, {:.3f} raw rms; depth camera fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}",
                 j.pixels, observations.size(), j.rms_raw, j.depth.camera_matrix(0, 0), j.depth.camera_matrix(1, 1),
                 j.depth.camera_matrix(0, 2), j.depth.camera_matrix(1, 2));
    for (std::size_t i = 0; i < observed.size(); ++i) {
      observed[i]->samples = PlaneSamples({observations[i]}, j.depth, j.depth_from_colour);
    }
  };
  // The quads' views, and the extrinsics fitted to them with the depth
  // camera held (`fitted` when the depth camera step fitted them already).
  const auto fitted_views = [&] {
    std::vector<ExtrinsicsView> views;
    for (const Frame& q : quads)
      if (q->kind == Kind::kBoard && !q->rejection && q->quad) views.push_back({q->colour_from_board, *q->quad, q->board_velocity, {}});
    return views;
  };
  const auto adopt_extrinsics = [&](std::vector<ExtrinsicsView> views, std::optional<ExtrinsicsResult> fitted = std::nullopt) {
    result.extrinsics_views = std::move(views);
    if (!fitted && result.extrinsics_views.size() < 3) return;
    const ExtrinsicsResult e = fitted ? std::move(*fitted)
                                      : RunExtrinsicsCalibration(options.extrinsics, board, result.cameras.depth,
                                                                 result.extrinsics_views, result.cameras.depth_from_colour);
    result.cameras.depth_from_colour = e.depth_from_colour;
    result.cameras.extrinsics_rms_px = e.rms_px;
    result.cameras.extrinsics_views = e.views;
    result.cameras.extrinsics_translation_sigma_m = e.translation_sigma_m;
    result.cameras.depth_delay_s = e.delay_s;
    if (e.delay_s) spdlog::info("the board moved: depth images lag colour by {:.1f} ms", 1e3 * *e.delay_s);
  };
  // The depth camera from the outlines, coarse to fine (pipeline/depth_camera_step.h):
  // each board frame's outline is found again where the fitted camera puts it.
  const auto calibrate_depth_camera = [&] {
    std::vector<Frame> frames;
    std::vector<OutlineFrame> outline_frames;
    for (const Frame& q : quads) {
      if (q->kind != Kind::kBoard || !q->detection || (q->rejection && q->rejection->stage != "depthboard_quad")) continue;
      frames.push_back(q);
      OutlineFrame& o = outline_frames.emplace_back();
      o.colour_from_board = q->colour_from_board;
      o.board_velocity = q->board_velocity;
      o.quad = q->rejection ? std::nullopt : q->quad;
      o.raw = &q->raw;
      o.reading = options.quad.reading;
      o.detection = &*q->detection;
      o.find_outline = [&, f = q.get()](const CameraIntrinsics& depth, const Eigen::Isometry3d& depth_from_colour) {
        std::array<Eigen::Vector2d, 4> predicted;
        for (int k = 0; k < 4; ++k) predicted[k] = depth.Project(depth_from_colour * f->colour_from_board * outline[k]);
        const double uncertainty = std::min(options.nominal_prediction_px, PredictionUncertaintyPx(depth, predicted));
        return FindOutline(options.quad, options.still_average, f->still_neighbours, f->raw, predicted, uncertainty);
      };
    }
    DepthCameraStepResult step = CalibrateDepthCameraFromOutlines(options.extrinsics, board, result.cameras.colour, result.cameras.depth,
                                                                  result.cameras.depth_from_colour, outline_frames);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      frames[i]->still_neighbours.clear();
      frames[i]->rejection.reset();
      frames[i]->quad.reset();
      Take(*frames[i], std::move(step.quads[i]), &frames[i]->quad);
    }
    if (step.not_fitted) {  // the run stops once the graph is drained: a nominal camera would be a silent guess
      depth_camera_failure = *step.not_fitted;
      return;
    }
    result.cameras.depth = step.depth;
    result.cameras.depth_intrinsics_source = "depth_outlines";
    result.cameras.depth_edge_offset_px = step.extrinsics.edge_offset_px;
    if (step.loosely_pinned) {
      result.cameras.depth_intrinsics_warning = *step.loosely_pinned;
      spdlog::warn("{}", *step.loosely_pinned);
    }
    adopt_extrinsics(fitted_views(), std::move(step.extrinsics));
  };
  Pass fit_extrinsics(g, flow::serial, [&](Frame f, Pass::output_ports_type& out) {
    quads.push_back(f);
    if (static_cast<std::int64_t>(quads.size()) < second_barrier) return;
    if (plane_mode) {
      clocks.Time(kExtrinsics, fit_planes);
    } else if (depth_camera_from_outlines) {
      clocks.Time(kExtrinsics, calibrate_depth_camera);
    } else {
      clocks.Time(kExtrinsics, [&] { adopt_extrinsics(fitted_views()); });
    }
    for (const Frame& q : quads) {
      if (q->kind == Kind::kBoard) std::get<0>(out).try_put(q);
      else std::get<1>(out).try_put(q);
    }
    quads.clear();
  });

  flow::function_node<Frame, Frame> pose_and_pair(g, flow::unlimited, [&](Frame f) {
    if (plane_mode) {  // the joint plane fit paired them already
      f->raw.release();
      return f;
    }
    Guarded(*f, "depth_pose", [&] {
      clocks.Time(kPosePair, [&] {
        const auto in_depth = RunDepthPose(options.depth_pose, board, result.cameras.depth, *f->quad);
        if (!Accepted(in_depth)) {
          f->rejection = std::get<Rejection>(in_depth);
          return;
        }
        const PairingInput input{f->index, f->pose, f->time_s, f->motion_px, f->velocity_px_s, f->raw,
                                 std::get<BoardInDepth>(in_depth), result.cameras, f->colour_from_board,
                                 f->colour_pose_covariance};
        auto paired = RunPairing(options.pairing, input);
        if (Accepted(paired)) {
          f->samples = std::move(std::get<std::vector<PairedSample>>(paired));
        } else {
          f->rejection = std::get<Rejection>(paired);
        }
      });
    });
    f->raw.release();
    return f;
  });

  flow::function_node<Frame, Frame> clean_snapshot(g, flow::unlimited, [&](Frame f) {
    Guarded(*f, "planar_cleanup", [&] {
      Take(*f, clocks.Time(kPlanarClean, [&] { return RunPlanarCleanup(options.planar, result.cameras.depth, f->raw, f->index); }),
           &f->snapshot);
    });
    f->raw.release();
    return f;
  });

  flow::function_node<Frame, flow::continue_msg> collect(g, flow::serial, [&](Frame f) {
    finish(f);
    progress.Update(++done);
    return flow::continue_msg();
  });

  flow::make_edge(read_boards, detect);
  flow::make_edge(read_ir, detect);
  flow::make_edge(read_planar, detect);
  flow::make_edge(detect, split);
  flow::make_edge(flow::output_port<0>(split), calibrate);
  flow::make_edge(flow::output_port<0>(calibrate), extract_quad);
  flow::make_edge(extract_quad, fit_extrinsics);
  flow::make_edge(flow::output_port<0>(fit_extrinsics), pose_and_pair);
  flow::make_edge(flow::output_port<1>(fit_extrinsics), clean_snapshot);
  flow::make_edge(pose_and_pair, collect);
  flow::make_edge(clean_snapshot, collect);
  read_boards.activate();
  read_ir.activate();
  read_planar.activate();
  g.wait_for_all();
  if (depth_camera_failure) {
    progress.Finish();
    std::map<std::string, int> reasons;  // what became of the board frames, as a failed pairing says
    for (const Frame& f : finished)
      if (f->kind == Kind::kBoard && f->rejection) ++reasons[f->rejection->stage + ": " + f->rejection->reason];
    std::string why;
    for (const auto& [reason, count] : reasons) why += "\n  " + std::to_string(count) + " x " + reason;
    throw InputError(session_dir.string() + ": the depth camera could not be calibrated: the session gives no depth " +
                     "intrinsics and has no IR chessboard recording, and from the depthboard outlines " +
                     *depth_camera_failure + ". Record more board poses (15 to 25, near to far, out to the image's " +
                     "corners), add an IR chessboard recording (record-session freenect --purpose ir_chessboard " +
                     "--add-to SESSION), or give the depth camera's intrinsics (record-session --describe). " +
                     "The board frames:" + why);
  }
  progress.Finish();

  // Gather, in recording order.
  std::sort(finished.begin(), finished.end(), [](const Frame& a, const Frame& b) {
    return std::tie(a->kind, a->index) < std::tie(b->kind, b->index);
  });
  static constexpr const char* kKindNames[] = {"ir_chessboard", "depthboard", "planar"};
  for (const Frame& f : finished) {
    result.frames.push_back({kKindNames[static_cast<int>(f->kind)], f->index, f->source_number, f->pose,
                             static_cast<int>(f->samples.size()), f->rejection,
                             f->quad ? std::optional<double>(f->quad->line_fit_rms_px) : std::nullopt});
    if (f->kind == Kind::kBoard) {
      ++result.board_frames;
      result.paired_frames += !f->samples.empty();
      result.samples.insert(result.samples.end(), f->samples.begin(), f->samples.end());
    }
    if (f->snapshot) result.snapshots.push_back(std::move(*f->snapshot));
  }
  result.samples = AssignRawRates(options.raw_rate, std::move(result.samples));
  if (planar_feed) {
    auto grid = clocks.Time(kGrid, [&] { return RunUndistortionGridBuild(options.grid, result.snapshots); });
    if (Accepted(grid)) {
      result.grid = std::move(std::get<UndistortionGrid>(grid));
    } else {
      result.grid_rejection = std::get<Rejection>(grid);
    }
  } else {
    result.grid_rejection = Rejection{"undistortion_grid", "the session has no planar recording"};
  }
  result.timings = clocks.Timings();
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace speckle
