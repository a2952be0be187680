#pragma once
// run-pipeline's flow graph: the thesis's procedure, automatic. The wiring
// is GraphRun::Run() in calibration_graph.cc: nodes declared, then edges.
//
// To add a per-frame stage (say, NAME, between two nodes of the graph):
//  1. The stage itself: stages/NAME.{h,cc}, a pure function
//     `StageResult<NameResult> RunName(const NameOptions&, inputs...)` that
//     returns its result or a Rejection{stage, reason} (stages/records.h),
//     never throws for bad data and reads no file. List the .cc in
//     stages/CMakeLists.txt. Its unit test, tests/NAME_test.cc, draws a
//     synthetic truth with tests/synthetic_views.h and joins
//     SPECKLE_STAGE_TESTS in tests/CMakeLists.txt (linked with
//     speckle_stages alone).
//     A stage that reads a raw depth image takes its units as a
//     `const DepthReading&` beside it (schemas/depth_reading.h): they are
//     the session's, not an option, and the graph hands on
//     step.options.reading, set once from the session.
//  2. Its options: `bool IsValid(std::string* why) const` on NameOptions,
//     its rules through an OptionCheck (schemas/option_check.h); a
//     `NameOptions name;` field of PipelineOptions (pipeline_options.h) and
//     `.Part("name", name)` in PipelineOptions::IsValid (pipeline_options.cc).
//     Its result on a frame: an `std::optional<NameResult>` field of
//     FrameWork (frame_work.h).
//  3. Its clock: an entry in StageId and in kStageNames (stage_clocks.h);
//     report.json's stage_seconds lists it from there.
//  4. Its step: `void Name(const StepContext& step, FrameWork& f)` in
//     steps/frame_steps.{h,cc}: `Guarded(f, "NAME", ...)` turns an escaping
//     exception into the frame's rejection, `Take(f, step.clocks.Time(kName,
//     [&] { return RunName(step.options.name, ...); }), &f.name)` keeps the
//     result or the rejection. A frame already rejected is passed on.
//     What a frame still holds depends on where the stage sits: the colour
//     (or IR) image only before `detect` (DetectBoards releases it), the raw
//     depth image until pose_and_pair / clean_snapshot release it. The names
//     Guarded and the Rejection give (report.json's rejection stage) are
//     the stage's own word, e.g. "depthboard_quad"; kStageNames is the clock's.
//  5. Its node, in GraphRun::Run():
//       flow::function_node<Frame, Frame> name(g, flow::unlimited, [&](Frame f) {
//         Name(step, *f);
//         return f;
//       });
//     and the edge it sits on made two: make_edge(before, name),
//     make_edge(name, after). Before `detect` the messages are Batches of
//     consecutive frames from the three readers: there the node is a
//     function_node<Batch, Batch> looping over the batch, and the readers'
//     edges go to it. A stage that needs every frame at once is a barrier: a
//     Route node with Barrier(expected, step, port_of), as calibrate_cameras is.
//  6. Only for what it finds for the whole session (a rejection is counted
//     and reported already): a field of PipelineResult
//     (pipeline_result.h), filled in GraphRun::Result() or GraphOutcome;
//     into report.json in pipeline/artifact_json.cc.
//  7. calibration_graph_test runs the graph on frames made in memory: a
//     case there shows the stage's effect (or its rejection) end to end.
//     Then `clang-format -i` what you touched (stage_clocks.h reflows) and
//     `cd build && ctest -L fast`.
#include <filesystem>
#include <functional>
#include <optional>

#include "pipeline/frame_work.h"
#include "pipeline/pipeline_options.h"
#include "pipeline/pipeline_result.h"
#include "schemas/session_manifest.h"

namespace speckle {

// One recording as the graph reads it: `next` gives its frames in recording
// order, then null. Called from one thread at a time.
struct RecordingStream {
  std::int64_t frames = 0;
  std::function<Frame()> next;
};

// What one run of the graph reads: the session's description and its
// recordings (the depthboard's required, planar and IR when present).
struct GraphInput {
  std::filesystem::path session_dir;  // named in errors
  SessionManifest manifest;
  cv::Size depth_size;  // of the depthboard recording
  RecordingStream boards;
  std::optional<RecordingStream> planar, ir;
};

// Runs every stage on `input`'s frames. Throws InputError when the session
// cannot be calibrated at all (no board described); frame-level problems
// are FrameOutcome rejections. The session-directory form below opens the
// recordings and calls this; tests call it on frames made in memory.
PipelineResult RunCalibrationGraph(const GraphInput& input, const PipelineOptions& options);

// Reads the session's recordings (depthboard required; planar and
// ir_chessboard used when present) and runs every stage. Throws InputError
// when the session cannot be calibrated at all (no board description, no
// depthboard recording); frame-level problems are FrameOutcome rejections.
PipelineResult RunCalibrationGraph(const std::filesystem::path& session_dir, const PipelineOptions& options);

// The stages' options for a session's depth units: one no-reading rule
// (schemas/depth_reading.h) for every stage, and the board-plane fits in the
// units' base form (linear_mm for millimetres). RunCalibrationGraph applies
// it once to the options it is given and hands the result on
// (PipelineResult::options).
PipelineOptions ForDepthUnits(PipelineOptions options, DepthUnits units);

}  // namespace speckle
