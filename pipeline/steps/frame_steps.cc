#include "pipeline/steps/frame_steps.h"

#include "pipeline/steps/depth_camera_step.h"

namespace speckle {

void DetectBoards(const StepContext& step, Batch& batch) {
  const ChessboardDetection* previous = nullptr;
  for (const Frame& f : batch) {
    Guarded(*f, "chessboard", [&] {
      if (f->recording == RecordingPurpose::kPlanar) return;
      const cv::Mat& image = f->recording == RecordingPurpose::kIrChessboard ? f->ir : f->colour;
      if (previous) {
        auto tracked = step.clocks.Time(
            kTrack, [&] { return RunChessboardTracking(step.options.tracking, step.board, image, *previous); });
        if (Accepted(tracked)) f->detection = std::move(std::get<ChessboardDetection>(tracked));
      }
      if (!f->detection) {
        Take(*f,
             step.clocks.Time(kDetect,
                              [&] { return RunChessboardDetection(step.options.detection, step.board, image); }),
             &f->detection);
      }
      f->colour.release();  // only detections are needed from here on
      f->ir.release();
    });
    if (f->rejection) f->raw.Release();
    previous = f->detection ? &*f->detection : nullptr;
  }
}

void ExtractOutline(const StepContext& step, const CameraCalibration& cameras, bool plane_mode, double uncertainty_px,
                    FrameWork& f) {
  Guarded(f, plane_mode ? "board_region" : "depthboard_quad", [&] {
    const auto outline = OutlineCorners(step.board);
    std::array<Eigen::Vector2d, 4> predicted;
    for (int k = 0; k < 4; ++k)
      predicted[k] = cameras.depth.Project(cameras.depth_from_colour * f.colour_from_board * outline[k]);
    if (plane_mode) {
      const double square_px = (predicted[1] - predicted[0]).norm() / step.board.squares_x;
      Take(f,
           step.clocks.Time(kQuad,
                            [&] {
                              return RunBoardRegion(step.options.board_region, f.raw.Image(), step.options.reading,
                                                    predicted, square_px);
                            }),
           &f.region);
    } else {
      Take(f,
           step.clocks.Time(kQuad,
                            [&] {
                              return FindOutline(step.options, f.still_neighbours, f.raw, predicted, uncertainty_px,
                                                 &cameras.depth, &step.dark_border);
                            }),
           &f.quad);
    }
  });
}

void PoseAndPair(const StepContext& step, const CameraCalibration& cameras, FrameWork& f) {
  Guarded(f, "depth_pose", [&] {
    step.clocks.Time(kPosePair, [&] {
      const auto in_depth = RunDepthPose(step.options.depth_pose, step.board, cameras.depth, *f.quad);
      if (!Accepted(in_depth)) {
        f.rejection = std::get<Rejection>(in_depth);
        return;
      }
      const cv::Mat raw = f.raw.Image();
      const PairingInput input{f.index,
                               f.pose,
                               f.time_s,
                               f.motion_px,
                               f.velocity_px_s,
                               raw,
                               std::get<BoardInDepth>(in_depth),
                               cameras,
                               f.colour_from_board,
                               f.colour_pose_covariance,
                               step.options.reading};
      auto paired = RunPairing(step.options.pairing, input);
      if (Accepted(paired)) {
        f.samples = std::move(std::get<std::vector<PairedSample>>(paired));
      } else {
        f.rejection = std::get<Rejection>(paired);
      }
    });
  });
}

void CleanSnapshot(const StepContext& step, const CameraIntrinsics& depth, FrameWork& f) {
  Guarded(f, "planar_cleanup", [&] {
    WallMask segmented;
    Take(f,
         step.clocks.Time(kPlanarClean,
                          [&] {
                            return RunPlanarCleanup(step.options.planar, depth, f.raw.Image(), step.options.reading,
                                                    f.index, &segmented);
                          }),
         &f.snapshot);
    if (f.rejection && !segmented.wall.empty()) f.rejected_wall = std::move(segmented);
  });
}

}  // namespace speckle
