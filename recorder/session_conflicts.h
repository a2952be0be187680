#pragma once
// Whether a plan's recordings may join an existing session. A session is one
// sensor seen through one driver, in one depth unit, with one image size per
// stream and at most one recording per purpose; the pipeline relies on all of
// these. Every difference is stated with the field and both values, so the
// user can tell a wrong dump from a wrong flag.
#include <filesystem>
#include <string>
#include <vector>

#include "recorder/frame_source.h"
#include "schemas/session_manifest.h"

namespace speckle {

struct SessionMerge {
  // The session's manifest with blanks (serial, label, rig, cameras, notes it
  // did not know) filled from the plan; its recordings are the session's own.
  SessionManifest manifest;
  std::vector<std::string> conflicts;  // empty = the plan may be added
};

// `session` is the manifest read from `session_dir`; the existing recordings'
// headers are read for their image sizes. Throws InputError only when an
// existing recording cannot be read.
SessionMerge MergeIntoSession(const std::filesystem::path& session_dir, const SessionManifest& session,
                              const SessionPlan& plan);

// Walls added to a session that has some become planar-2.h5, planar-3.h5,
// ...: run-pipeline reads every planar recording (Xiang's set keeps 5 walls
// among its boards and 10 more in wall/). Other purposes stay one each.
// The same folder added again is refused (MergeIntoSession).
void NameFurtherWalls(const SessionManifest& session, SessionPlan& plan);

}  // namespace speckle
