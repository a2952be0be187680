#pragma once
// session.json: what a session directory holds and how it was recorded.
// Spec: session_format.md. Reading rejects unknown schema versions and names
// the offending field; writing goes through a temporary file and a rename.
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "schemas/depth_units.h"

namespace speckle {

// Version 2 added the optional "cameras"; version 1 files are still read.
inline constexpr int kSessionSchemaVersion = 2;
inline constexpr int kOldestSessionSchemaVersion = 1;
inline constexpr const char* kSessionSchemaName = "speckle.session";
inline constexpr const char* kSessionFileName = "session.json";

// Why a recording was made; the pipeline picks its stages by purpose.
enum class RecordingPurpose { kDepthboard, kPlanar, kIrChessboard, kFree };
std::string ToString(RecordingPurpose purpose);
RecordingPurpose PurposeFromString(const std::string& text);  // throws InputError

// How the board's outline relates to the depth step the depth camera sees.
enum class BoardOutline {
  kChessboardEdge,  // the chessboard is mounted proud: its outer edge is the depth step
  kLargerBoard,     // a board larger than the printed chessboard (toolbox data sets)
  kUnknown,
};
std::string ToString(BoardOutline outline);
BoardOutline BoardOutlineFromString(const std::string& text);

struct SensorInfo {
  std::string model = "kinect_v1";
  std::string label;   // the user's name for this unit
  std::string serial;  // device serial when known
};

// A chessboard square's side that a real board can have, in metres: what
// session.json's reader accepts and record-session's --square-size checks.
inline constexpr double kMinSquareSizeM = 1e-3, kMaxSquareSizeM = 1.0;
// Squares along each side of a board, as session.json may give them.
inline constexpr int kMinSquaresPerSide = 2, kMaxSquaresPerSide = 64;

struct RigInfo {
  int squares_x = 0;  // chessboard squares across (interior corners = squares - 1)
  int squares_y = 0;
  double square_size_m = 0.0;
  BoardOutline outline = BoardOutline::kUnknown;
  std::string notes;
};

// Intrinsics a user already has (e.g. from another toolbox); the pipeline
// uses them instead of calibrating that camera. With standard deviations
// they are a prior: the joint calibration refines the camera within them
// and every depth sigma carries them; a term whose sigma is 0 (all of them
// when none is given) is taken as exact.
struct KnownIntrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3
  std::array<double, 9> stddev{};      // fx, fy, cx, cy, k1, k2, p1, p2, k3
  bool HasPrior() const;               // any stddev above 0
};

struct RecordingEntry {
  std::string file;  // relative to the session directory
  RecordingPurpose purpose = RecordingPurpose::kFree;
  // Where the frames came from, so a session assembled from several dumps
  // says which dump each recording holds. Empty = not recorded (older files).
  std::string source;       // "sim", "fakenect", "frames", "freenect"
  std::string source_path;  // the dump or frame folder, or empty
};

struct SessionManifest {
  int schema_version = kSessionSchemaVersion;
  SensorInfo sensor;
  std::string driver;  // "libfreenect", "simulator", ...
  DepthUnits depth_units = DepthUnits::kRaw11Bit;
  std::string optics = "stock";                      // free label: "stock", "wide_angle", ...
  std::optional<RigInfo> rig;                        // absent when the session holds no board
  std::optional<KnownIntrinsics> colour_intrinsics;  // "cameras.colour", version 2
  std::optional<KnownIntrinsics> depth_intrinsics;   // "cameras.depth": the IR camera's geometry
  std::string notes;
  std::string created_utc;
  std::string tool_version;
  std::vector<RecordingEntry> recordings;
};

nlohmann::json ToJson(const SessionManifest& manifest);
// `origin` names the file in error messages.
SessionManifest SessionManifestFromJson(const nlohmann::json& json, const std::string& origin);

// Reads DIR/session.json. Throws InputError / SchemaVersionError.
SessionManifest ReadSessionManifest(const std::filesystem::path& session_dir);
// Writes DIR/session.json atomically (temporary file, fsync, rename).
void WriteSessionManifest(const std::filesystem::path& session_dir, const SessionManifest& manifest);

// Reads a partial session.json-like rig/sensor description (used by importers
// that take the rig from a file instead of flags); only known keys allowed.
RigInfo RigFromJson(const nlohmann::json& json, const std::string& origin);
KnownIntrinsics IntrinsicsFromJson(const nlohmann::json& json, const std::string& origin);
// Intrinsics built in code (from a ROS camera_info, say), held to the reader's rules; throws InputError naming origin.
KnownIntrinsics CheckedIntrinsics(const KnownIntrinsics& intrinsics, const std::string& origin);
nlohmann::json ToJson(const KnownIntrinsics& intrinsics);

}  // namespace speckle
