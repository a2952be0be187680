#pragma once
// session.json: what a session directory holds and how it was recorded.
// Spec: session_format.md. Reading rejects unknown schema versions and names
// the offending field; writing goes through a temporary file and a rename.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace speckle {

inline constexpr int kSessionSchemaVersion = 1;
inline constexpr const char* kSessionSchemaName = "speckle.session";
inline constexpr const char* kSessionFileName = "session.json";

enum class DepthUnits { kRaw11Bit, kMillimetre };
std::string ToString(DepthUnits units);
DepthUnits DepthUnitsFromString(const std::string& text);  // throws InputError

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

struct RigInfo {
  int squares_x = 0;  // chessboard squares across (interior corners = squares - 1)
  int squares_y = 0;
  double square_size_m = 0.0;
  BoardOutline outline = BoardOutline::kUnknown;
  std::string notes;
};

struct RecordingEntry {
  std::string file;  // relative to the session directory
  RecordingPurpose purpose = RecordingPurpose::kFree;
};

struct SessionManifest {
  int schema_version = kSessionSchemaVersion;
  SensorInfo sensor;
  std::string driver;  // "libfreenect", "simulator", ...
  DepthUnits depth_units = DepthUnits::kRaw11Bit;
  std::string optics = "stock";  // free label: "stock", "wide_angle", ...
  std::optional<RigInfo> rig;  // absent when the session holds no board
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

}  // namespace speckle
