#include "pipeline/graph_outcome.h"

#include <algorithm>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "schemas/errors.h"

namespace speckle {
namespace {

int RecordingRank(RecordingPurpose r) {
  switch (r) {
    case RecordingPurpose::kIrChessboard:
      return 0;
    case RecordingPurpose::kDepthboard:
      return 1;
    default:
      return 2;
  }
}

// Frame f's slice of the board-plane perturbations, before its samples join
// result.samples. Every paired frame has the same directions or none.
void AppendPlanePerturbations(const FrameWork& f, PipelineResult& result) {
  auto& all = result.plane_perturbations;
  if (result.samples.empty()) all.resize(f.plane_perturbations.size());
  if (all.size() != f.plane_perturbations.size())
    throw std::logic_error("frame " + std::to_string(f.index) + " has " + std::to_string(f.plane_perturbations.size()) +
                           " board-plane perturbations, earlier frames " + std::to_string(all.size()));
  for (std::size_t k = 0; k < all.size(); ++k)
    all[k].insert(all[k].end(), f.plane_perturbations[k].begin(), f.plane_perturbations[k].end());
}

}  // namespace

void GraphOutcome::Add(Frame frame) {
  finished_.push_back(std::move(frame));
  progress_.Update(static_cast<std::int64_t>(finished_.size()));
}

PipelineResult GraphOutcome::Gather() {
  progress_.Finish();
  std::sort(finished_.begin(), finished_.end(), [](const Frame& a, const Frame& b) {
    return std::make_pair(RecordingRank(a->recording), a->index) <
           std::make_pair(RecordingRank(b->recording), b->index);
  });
  PipelineResult result;
  for (const Frame& f : finished_) {
    const bool colour_view =
        f->IsBoard() && f->colour_only && f->detection && f->rejection && f->rejection->reason == kNoDepthImage;
    result.frames.push_back({ToString(f->recording), f->index, f->source_number, f->pose,
                             static_cast<int>(f->samples.size()), colour_view ? std::nullopt : f->rejection,
                             f->quad ? std::optional<double>(f->quad->line_fit_rms_px) : std::nullopt,
                             std::move(f->rejected_wall), colour_view});
    if (f->IsBoard()) {
      ++result.board_frames;
      result.colour_view_frames += colour_view;
      result.paired_frames += !f->samples.empty();
      if (!f->samples.empty()) AppendPlanePerturbations(*f, result);
      // With or without an outline: a board plane's depth samples pin the depth camera on their own (Herrera's joint
      // fit).
      if (!f->samples.empty() && f->detection)
        result.board_observations.push_back(
            {f->index, f->pose, f->colour_from_board, f->detection->corners, f->quad, f->board_velocity});
      result.samples.insert(result.samples.end(), std::make_move_iterator(f->samples.begin()),
                            std::make_move_iterator(f->samples.end()));
      std::vector<PairedSample>().swap(f->samples);  // held once, not twice
    }
    if (f->snapshot) result.snapshots.push_back(std::move(*f->snapshot));
  }
  return result;
}

std::string RejectionReasons(const std::map<std::string, int>& reasons) {
  std::string out;
  int total = 0, no_board = 0;
  for (const auto& [reason, count] : reasons) {
    out += "\n  " + std::to_string(count) + " x " + reason;
    total += count;
    if (reason.starts_with("chessboard: no ") || reason.starts_with("IR chessboard: no ")) no_board += count;
  }
  if (2 * no_board > total)
    out +=
        "\n  if the board was in view, compare the chessboard looked for with it: session.json's rig.squares "
        "counts squares, not inner corners (a board of 9 x 7 squares is looked for as 8x6)";
  return out;
}

void GraphOutcome::ThrowDepthCameraFailure(const std::filesystem::path& session_dir, const std::string& why) {
  progress_.Finish();
  std::map<std::string, int> reasons;  // what became of the board frames, as a failed pairing says
  int ir_frames = 0, ir_found = 0;
  for (const Frame& f : finished_) {
    if (f->recording == RecordingPurpose::kIrChessboard) {
      ++ir_frames;
      ir_found += f->detection.has_value();
      if (f->rejection) ++reasons["IR " + f->rejection->stage + ": " + f->rejection->reason];
    } else if (f->IsBoard() && f->rejection) {
      ++reasons[f->rejection->stage + ": " + f->rejection->reason];
    }
  }
  // The IR recording is named as it is: a session with one whose chessboard
  // was never found was told it had none (issue 47's outside probe).
  const std::string ir = ir_frames == 0
                             ? "has no IR chessboard recording"
                             : fmt::format(
                                   "its IR chessboard recording calibrated no camera (the chessboard found in {} of {} "
                                   "frames)",
                                   ir_found, ir_frames);
  const std::string add_ir = ir_frames == 0 ? ", add an IR chessboard recording (record-session freenect --purpose "
                                              "ir_chessboard --add-to SESSION)"
                                            : "";
  throw InputError(session_dir.string() + ": the depth camera could not be calibrated: the session gives no depth " +
                   "intrinsics and " + ir + ", and from the depthboard outlines " + why +
                   ". Record more board poses (15 to 25, near to far, out to the image's corners)" + add_ir +
                   ", or give the depth camera's intrinsics (record-session --describe)." +
                   (reasons.empty() ? std::string() : " The frames:" + RejectionReasons(reasons)));
}

}  // namespace speckle
