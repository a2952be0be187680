#pragma once
// Imports a folder of numbered frames as Kinect calibration toolboxes store
// them (Herrera's, Xiang's): NNNN-c1.jpg colour, NNNN-d.pgm raw depth (a
// standard big-endian PGM with maxval 2047 or 2048). A number may have only
// one of the two, and colour may be larger than depth (1280x1024).
#include <filesystem>
#include <optional>

#include "recorder/frame_source.h"

namespace speckle {

struct FramesImportOptions {
  // Purpose of the recording that holds frames with colour.
  RecordingPurpose paired_purpose = RecordingPurpose::kDepthboard;
  // Where depth-only frames go. Toolboxes record their flat-wall views this
  // way, hence planar; nullopt keeps them with the paired frames.
  std::optional<RecordingPurpose> depth_only_purpose = RecordingPurpose::kPlanar;
};

std::vector<PlannedRecording> PlanFramesImport(const std::filesystem::path& dir, const FramesImportOptions& options,
                                               std::vector<std::string>* notes);

}  // namespace speckle
