// The calibration flow graph, wired in one place:
//
//   read ir ──── detect (IR) ──────────────┐
//   read boards ─ detect or track (colour) ┼─ calibrate cameras ─ extract outline ─ fit extrinsics ─┬─ pose + pair ─
//   collect read planar ───────────────────────────┘     (barrier)        (or board region)    (barrier)     └─ clean
//   snapshot ─ collect
//
// Each node's body is a named step (pipeline/steps/): the per-frame ones in
// frame_steps.h, the barriers in camera_step.h and extrinsics_step.h. A
// barrier holds every frame until all are in, runs its step once, and
// routes the frames on; what it decides (the cameras) is what the nodes after
// it read.
//
// Boards larger than their chessboard have no outline at the chessboard's
// edge: "extract outline" then finds the board region, and "fit extrinsics"
// estimates depth intrinsics, extrinsics and depth model jointly from the
// board planes (Herrera et al.), which also yields the paired samples.
//
// With still_frames_averaged > 1, "extract outline" finds each outline in the
// median of the frames around it of the same still pose (the thesis averaged
// depth images by hand for this); pairing still reads each frame's own raw.
//
// Readers emit small batches of consecutive frames (board frames of a still
// pose track the board from one frame to the next inside a batch). Readers
// are serial (one HDF5 reader each); per-frame steps run in parallel. A frame
// that fails a step carries a Rejection on to the collector; no exception
// leaves a node.
#include "pipeline/calibration_graph.h"

#include <tbb/flow_graph.h>
#include <tbb/global_control.h>

#include <chrono>
#include <mutex>

#include "pipeline/frame_feed.h"
#include "pipeline/graph_outcome.h"
#include "pipeline/steps/camera_step.h"
#include "pipeline/steps/extrinsics_step.h"
#include "pipeline/steps/frame_steps.h"
#include "recorder/manifest_agreement.h"
#include "recorder/session_inspection.h"
#include "schemas/errors.h"
#include "stages/dark_border.h"

namespace speckle {
namespace {

namespace flow = tbb::flow;
using Route = flow::multifunction_node<Frame, std::tuple<Frame, Frame>>;

// A barrier's body: holds frames until `expected` are in, runs `step` on
// them once, then sends each on to the port `port_of` names (0 or 1).
template <typename Step, typename PortOf>
auto Barrier(std::int64_t expected, Step step, PortOf port_of) {
  return
      [held = std::make_shared<std::vector<Frame>>(), expected, step, port_of](Frame f, Route::output_ports_type& out) {
        held->push_back(std::move(f));
        if (static_cast<std::int64_t>(held->size()) < expected) return;
        step(*held);
        for (const Frame& h : *held) (port_of(*h) == 0 ? std::get<0>(out) : std::get<1>(out)).try_put(h);
        held->clear();
      };
}

// What the readers share: each frame's readings go into the session's
// coverage (for its dark border), and past the budget a frame's raw image is
// let go once read (pipeline/raw_depth.h). Readers run in parallel.
struct ReadFrames {
  explicit ReadFrames(const PipelineOptions& options) : budget(options.held_raw_frames), reading(options.reading) {}
  void Take(FrameWork& f) {
    if (!f.raw.Present()) return;
    {
      const std::lock_guard lock(mutex);
      AddReadings(f.raw.Image(), reading, ever_read);
    }
    if (!budget.Take()) f.raw.LetGo();
  }
  HeldRawBudget budget;
  const DepthReading reading;
  std::mutex mutex;
  cv::Mat ever_read;
};

// A reader's body for an input_node; `source` is null for a recording the session lacks.
auto Reader(StageClocks& clocks, ReadFrames& read, const RecordingStream* source, int batch_frames) {
  return [&clocks, &read, source, batch_frames](tbb::flow_control& control) -> Batch {
    Batch batch;
    while (source && static_cast<int>(batch.size()) < batch_frames) {
      Frame frame = clocks.Time(kRead, [&] { return source->next(); });
      if (!frame) break;
      read.Take(*frame);
      batch.push_back(std::move(frame));
    }
    if (batch.empty()) control.stop();
    return batch;
  };
}

const RecordingEntry* FindRecording(const SessionManifest& m, RecordingPurpose purpose) {
  for (const auto& r : m.recordings)
    if (r.purpose == purpose) return &r;
  return nullptr;
}

// The session's recordings, opened: the depthboard's is required; every
// planar recording is read, one after another (walls added twice).
struct Feeds {
  Feeds(const std::filesystem::path& session_dir, const SessionManifest& manifest) {
    const RecordingEntry* board_entry = FindRecording(manifest, RecordingPurpose::kDepthboard);
    if (!board_entry)
      throw InputError(session_dir.string() + ": the session has no depthboard recording to calibrate from");
    const auto open = [&](const RecordingEntry& entry, std::int64_t first_index) {
      auto feed = std::make_unique<FrameFeed>(session_dir / entry.file, entry.purpose, first_index);
      RefuseManifestDisagreements(session_dir, entry, feed->reader().header(), manifest);
      // What session-info calls invalid is not calibrated: the time effects read these times.
      if (const std::string times = ImpossibleTimes(feed->reader(), (session_dir / entry.file).string());
          !times.empty())
        throw InputError(times + " (session-info lists every such problem)");
      return feed;
    };
    boards = open(*board_entry, 0);
    for (const auto& entry : manifest.recordings) {
      if (entry.purpose != RecordingPurpose::kPlanar) continue;
      const std::int64_t first = planar.empty() ? 0 : planar.back()->first_index() + planar.back()->count();
      planar.push_back(open(entry, first));
    }
    if (const auto* entry = FindRecording(manifest, RecordingPurpose::kIrChessboard)) ir = open(*entry, 0);
    std::vector<FrameFeed*> all{boards.get()};
    for (auto& feed : planar) all.push_back(feed.get());
    if (ir) all.push_back(ir.get());
    std::vector<const RecordingReader*> readers;
    for (const FrameFeed* feed : all) readers.push_back(&feed->reader());
    const std::int64_t origin = FirstHostTimeNs(readers);
    for (FrameFeed* feed : all) feed->StartClockAt(origin);
    const auto& header = boards->reader().header();
    if (!header.colour_size || !header.depth_size) {
      throw InputError(boards->reader().path().string() + ": a depthboard recording needs colour and depth frames");
    }
  }
  std::unique_ptr<FrameFeed> boards, ir;
  std::vector<std::unique_ptr<FrameFeed>> planar;
};

std::vector<FrameFeed*> PlanarFeeds(const Feeds& feeds) {
  std::vector<FrameFeed*> out;
  for (const auto& f : feeds.planar) out.push_back(f.get());
  return out;
}

// The feeds read one after another as one stream; none for none.
std::optional<RecordingStream> SourceOf(std::vector<FrameFeed*> feeds) {
  std::erase(feeds, nullptr);
  if (feeds.empty()) return std::nullopt;
  std::int64_t frames = 0;
  for (const FrameFeed* f : feeds) frames += f->count();
  auto at = std::make_shared<std::size_t>(0);
  return RecordingStream{frames, [feeds, at]() -> Frame {
                           for (; *at < feeds.size(); ++*at)
                             if (Frame f = feeds[*at]->Next()) return f;
                           return nullptr;
                         }};
}

std::int64_t Total(const GraphInput& in) {
  return in.boards.frames + (in.planar ? in.planar->frames : 0) + (in.ir ? in.ir->frames : 0);
}

BoardGeometry Board(const std::filesystem::path& session_dir, const SessionManifest& manifest) {
  if (!manifest.rig) {
    throw InputError((session_dir / kSessionFileName).string() +
                     ": no rig described; the pipeline needs the board's squares and square size");
  }
  return {manifest.rig->squares_x, manifest.rig->squares_y, manifest.rig->square_size_m};
}

// One run of the graph: what it reads, and what its barriers decide, which
// the nodes after them read.
struct GraphRun {
  GraphRun(const GraphInput& input, const PipelineOptions& options)
      : input(input),
        session_dir(input.session_dir),
        manifest(input.manifest),
        options(ForDepthUnits(options, manifest.depth_units)),
        board(Board(session_dir, manifest)),
        plane_mode(manifest.rig->outline != BoardOutline::kChessboardEdge),
        outcome("run-pipeline", Total(input)) {}

  void Run();
  PipelineResult Result(std::chrono::steady_clock::time_point start);

  // The first barrier's step, then the second's.
  void CalibrateCamerasStep(std::vector<Frame>& frames) {
    clocks.Time(kCalibrate, [&] {
      dark_border = DarkBorder(read.ever_read);
      cameras = CalibrateCameras({options, board, manifest, input.depth_size, plane_mode}, frames);
    });
  }
  void FitExtrinsicsStep(std::vector<Frame>& frames) {
    ExtrinsicsMode mode = ExtrinsicsMode::kOutlines;
    if (options.held_cameras)
      mode = ExtrinsicsMode::kHeld;
    else if (plane_mode)
      mode = ExtrinsicsMode::kBoardPlanes;
    else if (cameras.depth_camera_from_outlines)
      mode = ExtrinsicsMode::kDepthCameraFromOutlines;
    clocks.Time(kExtrinsics,
                [&] { extrinsics = FitExtrinsics(options, board, mode, cameras.cameras, dark_border, frames); });
  }
  // How far the first outlines may be from where the cameras put them: held
  // cameras (check) may have moved since they were calibrated.
  double OutlineGatePx() const {
    return cameras.depth_camera_from_outlines || options.held_cameras ? options.nominal_prediction_px : 0.0;
  }

  const GraphInput& input;
  const std::filesystem::path session_dir;
  const SessionManifest& manifest;
  const PipelineOptions options;  // for the session's depth units
  const BoardGeometry board;
  const bool plane_mode;
  StageClocks clocks;
  ReadFrames read{options};
  cv::Mat dark_border;  // once the first barrier has seen every frame
  const StepContext step{options, board, clocks, dark_border};
  CameraStepResult cameras;
  ExtrinsicsStepResult extrinsics;
  GraphOutcome outcome;
};

void GraphRun::Run() {
  // Where the barriers send frames: port 0 or 1.
  const auto ir_to_collector = [](const FrameWork& f) {
    return f.recording == RecordingPurpose::kIrChessboard ? 1 : 0;
  };
  const auto planar_to_cleanup = [](const FrameWork& f) { return f.IsBoard() ? 0 : 1; };
  const std::int64_t ir_frames = input.ir ? input.ir->frames : 0;

  flow::graph g;
  flow::input_node<Batch> read_boards(g, Reader(clocks, read, &input.boards, std::max(1, options.batch_frames)));
  flow::input_node<Batch> read_planar(g, Reader(clocks, read, input.planar ? &*input.planar : nullptr, 1));
  flow::input_node<Batch> read_ir(g, Reader(clocks, read, input.ir ? &*input.ir : nullptr, 1));
  flow::function_node<Batch, Batch> detect(g, flow::unlimited, [&](Batch b) {
    DetectBoards(step, b);
    return b;
  });
  flow::multifunction_node<Batch, std::tuple<Frame>> split(g, flow::unlimited, [](const Batch& b, auto& out) {
    for (const Frame& f : b) std::get<0>(out).try_put(f);
  });
  Route calibrate_cameras(g, flow::serial,
                          Barrier(
                              Total(input), [&](auto& all) { CalibrateCamerasStep(all); }, ir_to_collector));
  flow::function_node<Frame, Frame> extract_outline(g, flow::unlimited, [&](Frame f) {
    if (f->IsBoard()) ExtractOutline(step, cameras.cameras, plane_mode, OutlineGatePx(), *f);
    if (!cameras.depth_camera_from_outlines) f->still_neighbours.clear();  // the fine outlines need them again
    return f;
  });
  Route fit_extrinsics(g, flow::serial,
                       Barrier(
                           Total(input) - ir_frames, [&](auto& all) { FitExtrinsicsStep(all); }, planar_to_cleanup));
  flow::function_node<Frame, Frame> pose_and_pair(g, flow::unlimited, [&](Frame f) {
    if (!plane_mode) PoseAndPair(step, extrinsics.cameras, *f);  // the board planes paired them already
    f->raw.Release();
    return f;
  });
  flow::function_node<Frame, Frame> clean_snapshot(g, flow::unlimited, [&](Frame f) {
    CleanSnapshot(step, extrinsics.cameras.depth, *f);
    f->raw.Release();
    return f;
  });
  flow::function_node<Frame, flow::continue_msg> collect(g, flow::serial, [&](Frame f) {
    outcome.Add(std::move(f));
    return flow::continue_msg();
  });

  for (auto* reader : {&read_boards, &read_ir, &read_planar}) flow::make_edge(*reader, detect);
  flow::make_edge(detect, split);
  flow::make_edge(flow::output_port<0>(split), calibrate_cameras);
  flow::make_edge(flow::output_port<0>(calibrate_cameras), extract_outline);
  flow::make_edge(flow::output_port<1>(calibrate_cameras), collect);
  flow::make_edge(extract_outline, fit_extrinsics);
  flow::make_edge(flow::output_port<0>(fit_extrinsics), pose_and_pair);
  flow::make_edge(flow::output_port<1>(fit_extrinsics), clean_snapshot);
  flow::make_edge(pose_and_pair, collect);
  flow::make_edge(clean_snapshot, collect);
  for (auto* reader : {&read_boards, &read_ir, &read_planar}) reader->activate();
  g.wait_for_all();
}

PipelineResult GraphRun::Result(std::chrono::steady_clock::time_point start) {
  if (extrinsics.depth_camera_failure) outcome.ThrowDepthCameraFailure(session_dir, *extrinsics.depth_camera_failure);
  PipelineResult result = outcome.Gather();
  result.options = options;
  result.board = board;
  result.depth_units = manifest.depth_units;
  result.still_frames_averaged = std::max(1, options.still_frames_averaged);
  result.cameras = extrinsics.cameras;
  result.extrinsics_views = std::move(extrinsics.views);
  if (!plane_mode && manifest.depth_units == DepthUnits::kRaw11Bit)
    result.board_size_in_depth = MeasureBoardSizeInDepth({}, board, result.extrinsics_views, result.cameras.depth,
                                                         result.cameras.depth_from_colour);
  result.planar_recording = input.planar.has_value();
  result.timings = clocks.Timings();
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace

PipelineOptions ForDepthUnits(PipelineOptions options, DepthUnits units) {
  options.reading = DepthReading(units);
  if (units == DepthUnits::kMillimetre) options.joint_plane.form = model::BaseForm::kLinearMm;
  return options;
}

PipelineResult RunCalibrationGraph(const GraphInput& input, const PipelineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::optional<tbb::global_control> thread_limit;
  if (options.threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, options.threads);
  GraphRun run(input, options);
  run.Run();
  return run.Result(start);
}

PipelineResult RunCalibrationGraph(const std::filesystem::path& session_dir, const PipelineOptions& options) {
  const SessionManifest manifest = ReadSessionManifest(session_dir);
  Board(session_dir, manifest);  // a session without a rig is refused before its recordings are opened
  Feeds feeds(session_dir, manifest);
  GraphInput input{session_dir,
                   manifest,
                   *feeds.boards->reader().header().depth_size,
                   *SourceOf({feeds.boards.get()}),
                   SourceOf(PlanarFeeds(feeds)),
                   SourceOf({feeds.ir.get()})};
  return RunCalibrationGraph(input, options);
}

}  // namespace speckle
