#include "pipeline/steps/board_poses.h"

#include <algorithm>

#include "stages/rate_neighbours.h"

namespace speckle {

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

void GatherStillNeighbours(std::vector<Frame>& boards, int window) {
  if (window <= 1) return;
  for (std::size_t i = 0; i < boards.size(); ++i) {
    FrameWork& f = *boards[i];
    if (f.pose < 0 || !f.detection) continue;
    const auto same_pose = [&](std::size_t k) {
      return boards[k]->pose == f.pose && boards[k]->detection && boards[k]->raw.Present();
    };
    std::size_t first = i, last = i;  // inclusive
    while (static_cast<int>(last - first + 1) < window) {
      const bool before = first > 0 && same_pose(first - 1), after = last + 1 < boards.size() && same_pose(last + 1);
      if (!before && !after) break;
      // Alternate sides so the window stays centred where it can.
      if (after && (!before || last - i <= i - first))
        ++last;
      else
        --first;
    }
    for (std::size_t k = first; k <= last; ++k) f.still_neighbours.push_back(boards[k]->raw);
  }
}

}  // namespace speckle
