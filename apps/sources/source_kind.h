#pragma once
// record-session's SOURCE kinds (sim, fakenect:DIR, ...): one table, in
// source_table.cc, which also says how to add an importer. The command
// line's check of SOURCE, its help and the planning of a session all come
// from that table.
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "recorder/frame_source.h"
#include "recorder/sources/rosbag_source.h"

namespace speckle {

// The command-line values a source's planner reads: record-session's
// simulator, import, rosbag and live option groups.
struct SourceFlags {
  std::string scenario;  // sim: scenario JSON; empty: the default scenario
  std::optional<std::uint64_t> seed;
  bool realtime = false;
  std::string purpose;  // empty: the source's own default
  bool allow_unpaired = false;
  double max_pair_gap_ms = 20;
  std::string depth_only = "planar";
  RosbagImportOptions rosbag;  // topics, --use-camera-info
  std::string depth_units = "auto";
  double duration_s = 0;
  int device = 0;
};

struct SourceKind {
  const char* name;  // what SOURCE is or starts with: "fakenect"
  // What follows "NAME:" ("DIR", "FILE"), as help shows it; nullptr: the
  // kind takes no path.
  const char* path;
  const char* description;  // one line of --help
  // Adds the recordings to `plan`, whose manifest holds on entry the
  // session's so far (defaults, or the one --add-to names), and sets what
  // the source knows of the session: driver, depth units, intrinsics.
  void (*plan)(const SourceFlags& flags, const std::string& path, SessionPlan& plan);
};

// Every kind, in the order help and messages list them (source_table.cc).
std::span<const SourceKind> SourceKinds();

// The rest comes from the table (source_kind.cc).
std::string SourceSyntax(const SourceKind& kind);  // "fakenect:DIR", "sim"
std::string SourceChoices();                       // "sim | freenect | fakenect:DIR | ...", for SOURCE's help
std::string SourceDescriptions();                  // one line per kind, for --help's description

// The session SOURCE makes, its manifest laid over `base`. A SOURCE that is
// no kind, or a path where the kind takes none or none where it takes one,
// is a CLI::ValidationError naming every kind (a usage error).
SessionPlan PlanSource(const std::string& source, const SourceFlags& flags, const SessionManifest& base);

}  // namespace speckle
