#pragma once
// Where a recording's own header and session.json disagree (its purpose, the
// source it came from, its depth units). Every tool that reads a session asks
// the same questions: session-info lists the answers as problems, and
// run-pipeline and apply-calibration refuse such a session, so that
// "valid: yes" means the other tools take it.
#include <filesystem>
#include <string>
#include <vector>

#include "recorder/recording_header.h"
#include "schemas/session_manifest.h"

namespace speckle {

std::vector<std::string> ManifestDisagreements(const RecordingEntry& entry, const RecordingHeader& header,
                                               const SessionManifest& manifest);

// InputError naming session.json and the recording when they disagree.
void RefuseManifestDisagreements(const std::filesystem::path& session_dir, const RecordingEntry& entry,
                                 const RecordingHeader& header, const SessionManifest& manifest);

}  // namespace speckle
