#include "recorder/session_conflicts.h"

#include <fmt/format.h>

#include <algorithm>
#include <tuple>

#include "recorder/recording_reader.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

// A value either side may not know (empty): both known and different is a
// conflict; known only to the new recording fills the session's blank.
void KnownMustAgree(const std::string& field, std::string& in_session, const std::string& in_new,
                    std::vector<std::string>& conflicts) {
  if (in_new.empty() || in_new == in_session) return;
  if (in_session.empty()) {
    in_session = in_new;
    return;
  }
  conflicts.push_back(fmt::format("{}: the session has \"{}\", the new recording \"{}\"", field, in_session, in_new));
}

std::string RigText(const std::optional<RigInfo>& rig) {
  if (!rig) return "none";
  return fmt::format("{}x{} squares of {:.1f} mm, outline {}", rig->squares_x, rig->squares_y,
                     rig->square_size_m * 1000, ToString(rig->outline));
}

std::string IntrinsicsText(const std::optional<KnownIntrinsics>& k) { return k ? ToJson(*k).dump() : ""; }

// Sensor, driver, optics, rig, known intrinsics and notes.
void MergeDescription(const SessionManifest& described, SessionManifest& merged, std::vector<std::string>& conflicts) {
  if (described.sensor.model != merged.sensor.model) {
    conflicts.push_back(fmt::format("sensor.model: the session has \"{}\", the new recording \"{}\"",
                                    merged.sensor.model, described.sensor.model));
  }
  KnownMustAgree("sensor.serial", merged.sensor.serial, described.sensor.serial, conflicts);
  KnownMustAgree("sensor.label", merged.sensor.label, described.sensor.label, conflicts);
  KnownMustAgree("driver", merged.driver, described.driver, conflicts);
  KnownMustAgree("optics", merged.optics, described.optics, conflicts);
  KnownMustAgree("notes", merged.notes, described.notes, conflicts);
  const bool same_rig = merged.rig && described.rig && RigText(merged.rig) == RigText(described.rig);
  if (!merged.rig) {
    merged.rig = described.rig;
  } else if (described.rig && !same_rig) {
    conflicts.push_back(
        fmt::format("rig: the session has {}, the new recording {}", RigText(merged.rig), RigText(described.rig)));
  }
  for (auto [name, in_session, in_new] :
       {std::tuple{"cameras.colour", &merged.colour_intrinsics, &described.colour_intrinsics},
        std::tuple{"cameras.depth", &merged.depth_intrinsics, &described.depth_intrinsics}}) {
    std::string session_text = IntrinsicsText(*in_session);
    KnownMustAgree(name, session_text, IntrinsicsText(*in_new), conflicts);
    if (!*in_session) *in_session = *in_new;
  }
}

void CheckDepthUnits(const SessionManifest& session, const SessionPlan& plan, std::vector<std::string>& conflicts) {
  for (const PlannedRecording& r : plan.recordings) {
    if (r.header.depth_size && r.header.depth_units != session.depth_units) {
      conflicts.push_back(fmt::format("depth_units: the session holds {} depth, {} would hold {}",
                                      ToString(session.depth_units), r.file, ToString(r.header.depth_units)));
    }
  }
}

std::string SizeText(const cv::Size& size) { return fmt::format("{}x{}", size.width, size.height); }

// Every stream keeps one image size across the session (the stages share one
// set of intrinsics per camera), and libfreenect's device.json, the factory
// registration constants of one Kinect, must be the same unit's.
void CheckRecordingHeaders(const fs::path& session_dir, const SessionManifest& session, const SessionPlan& plan,
                           std::vector<std::string>& conflicts) {
  for (const RecordingEntry& entry : session.recordings) {
    const RecordingHeader existing = RecordingReader(session_dir / entry.file).header();
    for (const PlannedRecording& r : plan.recordings) {
      for (auto [stream, in_session, in_new] : {std::tuple{"colour", existing.colour_size, r.header.colour_size},
                                                std::tuple{"depth", existing.depth_size, r.header.depth_size},
                                                std::tuple{"ir", existing.ir_size, r.header.ir_size}}) {
        if (in_session && in_new && *in_session != *in_new) {
          conflicts.push_back(fmt::format("image size: {} {} in the new {} differs from {} in {}", stream,
                                          SizeText(*in_new), r.file, SizeText(*in_session), entry.file));
        }
      }
      const std::string& ours = existing.device_registration_json;
      const std::string& theirs = r.header.device_registration_json;
      if (!ours.empty() && !theirs.empty() && ours != theirs) {
        conflicts.push_back(fmt::format(
            "sensor: the new {}'s device.json (factory registration constants) differs from {}'s: another Kinect",
            r.file, entry.file));
      }
    }
  }
}

std::string OriginText(const RecordingEntry& entry) {
  if (entry.source.empty()) return "";
  return ", from " + entry.source + (entry.source_path.empty() ? "" : " " + entry.source_path);
}

// One recording per purpose but walls (the pipeline picks recordings by
// purpose, and reads every planar one) and never a file over another.
void CheckNames(const fs::path& session_dir, const SessionManifest& session, const SessionPlan& plan,
                std::vector<std::string>& conflicts) {
  constexpr const char* kHowToProceed =
      "to keep both, give the new recording another --purpose, or import it into a new session with --out";
  for (const PlannedRecording& r : plan.recordings) {
    const auto same = std::find_if(session.recordings.begin(), session.recordings.end(), [&](const auto& e) {
      return (e.purpose == r.header.purpose && r.header.purpose != RecordingPurpose::kPlanar) || e.file == r.file;
    });
    const auto again = std::find_if(session.recordings.begin(), session.recordings.end(), [&](const auto& e) {
      return !e.source.empty() && !r.header.source_path.empty() && e.source == r.header.source &&
             e.source_path == r.header.source_path && e.purpose == r.header.purpose;
    });
    if (again != session.recordings.end()) {
      conflicts.push_back(
          fmt::format("{}: the session already holds this recording ({}{})", r.file, again->file, OriginText(*again)));
    } else if (same != session.recordings.end()) {
      conflicts.push_back(fmt::format("{}: the session already has a {} recording ({}{}); {}", r.file,
                                      ToString(same->purpose), same->file, OriginText(*same), kHowToProceed));
    } else if (fs::exists(fs::symlink_status(session_dir / r.file))) {
      conflicts.push_back(fmt::format(
          "{}: a file of that name is already in {} but session.json does not list it (left by an interrupted "
          "add?); move it out of the session first",
          r.file, session_dir.string()));
    }
  }
}

}  // namespace

SessionMerge MergeIntoSession(const fs::path& session_dir, const SessionManifest& session, const SessionPlan& plan) {
  SessionMerge merge{session, {}};
  MergeDescription(plan.manifest, merge.manifest, merge.conflicts);
  CheckDepthUnits(session, plan, merge.conflicts);
  CheckRecordingHeaders(session_dir, session, plan, merge.conflicts);
  CheckNames(session_dir, session, plan, merge.conflicts);
  return merge;
}

void NameFurtherWalls(const SessionManifest& session, SessionPlan& plan) {
  // Listed by the session or planned by another recording. A file left
  // beside the session that it does not list stays CheckNames' conflict.
  const auto taken = [&](const std::string& file, const PlannedRecording& self) {
    for (const auto& e : session.recordings)
      if (e.file == file) return true;
    for (const auto& r : plan.recordings)
      if (&r != &self && r.file == file) return true;
    return false;
  };
  const bool has_walls = std::any_of(session.recordings.begin(), session.recordings.end(),
                                     [](const auto& e) { return e.purpose == RecordingPurpose::kPlanar; });
  for (PlannedRecording& r : plan.recordings) {
    if (!has_walls || r.header.purpose != RecordingPurpose::kPlanar || !taken(r.file, r)) continue;
    const fs::path file(r.file);
    for (int n = 2;; ++n) {
      const std::string name = fmt::format("{}-{}{}", file.stem().string(), n, file.extension().string());
      if (taken(name, r)) continue;
      r.file = name;
      break;
    }
  }
}

}  // namespace speckle
