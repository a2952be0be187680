#pragma once
// Imports a folder in the TUM RGB-D benchmark's layout (Sturm et al., 2012):
//
//   rgb.txt    "timestamp rgb/NAME.png" per line, '#' comments
//   depth.txt  "timestamp depth/NAME.png"
//   rgb/       8-bit colour PNG
//   depth/     16-bit PNG, 5000 per metre (millimetres x 5), 0 = no reading
//
// Colour and depth are associated as their associate.py does: nearest stamp
// within 20 ms (stamp_pairing.h); frames left without a partner are dropped,
// as that tool drops them, and counted in a note. Depth is stored in
// millimetres (value / 5), the session's depth_units "millimetre".
#include <filesystem>

#include "recorder/frame_source.h"

namespace speckle {

struct TumImportOptions {
  RecordingPurpose purpose = RecordingPurpose::kDepthboard;
  double max_pair_gap_s = 0.020;
};

// Reads both lists and checks every file they name (exists, a PNG of the
// right depth and size) before any frame is written. Throws InputError naming
// the file and line.
PlannedRecording PlanTumImport(const std::filesystem::path& dir, const TumImportOptions& options,
                               std::vector<std::string>* notes);

}  // namespace speckle
