#pragma once
// Imports a libfreenect `record` (fakenect) dump: INDEX.txt listing
// d-<host time>-<device timestamp>.pgm depth, r-...ppm colour and a-...dump
// accelerometer files, plus device.json when the recorder wrote one.
#include <filesystem>

#include "recorder/frame_source.h"

namespace speckle {

struct FakenectImportOptions {
  RecordingPurpose purpose = RecordingPurpose::kFree;
  // Colour and depth frames further apart than this (host clock) are unpaired.
  double max_pair_gap_s = 0.020;
  // Keep unpaired frames as single-stream pairs instead of rejecting the dump.
  bool allow_unpaired = false;
};

// Reads and checks INDEX.txt and every file it names (existence, sizes)
// before any frame is written. Throws InputError naming the file and line.
PlannedRecording PlanFakenectImport(const std::filesystem::path& dump_dir, const FakenectImportOptions& options,
                                    std::vector<std::string>* notes);

}  // namespace speckle
