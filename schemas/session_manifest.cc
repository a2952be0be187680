#include "schemas/session_manifest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <utility>

#include "schemas/atomic_file.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle {
namespace {

// One table per enum keeps names and parsing in step.
template <typename Enum, std::size_t N>
struct EnumNames {
  std::array<std::pair<Enum, const char*>, N> names;
  const char* what;

  std::string Name(Enum value) const {
    for (const auto& [v, n] : names)
      if (v == value) return n;
    throw std::logic_error(std::string("unnamed ") + what);
  }
  Enum Parse(const std::string& text) const {
    std::string expected;
    for (const auto& [v, n] : names) {
      if (text == n) return v;
      expected += (expected.empty() ? "" : ", ") + std::string(n);
    }
    throw InputError("unknown " + std::string(what) + " \"" + text + "\" (expected one of: " + expected + ")");
  }
};

constexpr EnumNames<DepthUnits, 2> kUnitNames{
    {{{DepthUnits::kRaw11Bit, "raw_11bit"}, {DepthUnits::kMillimetre, "millimetre"}}}, "depth units"};
constexpr EnumNames<RecordingPurpose, 4> kPurposeNames{{{{RecordingPurpose::kDepthboard, "depthboard"},
                                                         {RecordingPurpose::kPlanar, "planar"},
                                                         {RecordingPurpose::kIrChessboard, "ir_chessboard"},
                                                         {RecordingPurpose::kFree, "free"}}},
                                                       "recording purpose"};
constexpr EnumNames<BoardOutline, 3> kOutlineNames{{{{BoardOutline::kChessboardEdge, "chessboard_edge"},
                                                     {BoardOutline::kLargerBoard, "larger_board"},
                                                     {BoardOutline::kUnknown, "unknown"}}},
                                                   "board outline"};

// Wraps enum parsing so the message names the field.
template <typename Parse>
auto ParseField(JsonFields& fields, const std::string& key, Parse parse) {
  const auto text = fields.Required<std::string>(key);
  try {
    return parse(text);
  } catch (const InputError& e) {
    throw InputError(fields.Path(key) + ": " + e.what());
  }
}

}  // namespace

std::string ToString(DepthUnits units) { return kUnitNames.Name(units); }
DepthUnits DepthUnitsFromString(const std::string& text) { return kUnitNames.Parse(text); }
std::string ToString(RecordingPurpose purpose) { return kPurposeNames.Name(purpose); }
RecordingPurpose PurposeFromString(const std::string& text) { return kPurposeNames.Parse(text); }
std::string ToString(BoardOutline outline) { return kOutlineNames.Name(outline); }
BoardOutline BoardOutlineFromString(const std::string& text) { return kOutlineNames.Parse(text); }

namespace {

// The optional standard deviations: none is an exact camera. A sigma as
// large as its focal length (or a principal point's as the image) is a unit
// or typing slip, not a prior.
std::array<double, 9> StddevFromJson(JsonFields& f, const KnownIntrinsics& k) {
  static const char* kKey = "stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3";
  const auto s = f.Optional<std::vector<double>>(kKey, std::vector<double>(9, 0.0));
  if (s.size() != 9) throw InputError(f.Path(kKey) + ": expected 9 numbers (fx, fy, cx, cy, k1, k2, p1, p2, k3)");
  const double limits[9] = {0.5 * k.fx, 0.5 * k.fy, 0.5 * k.width, 0.5 * k.height, 10, 10, 10, 10, 10};
  static const char* kNames[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
  std::array<double, 9> out{};
  for (std::size_t i = 0; i < 9; ++i) {
    if (!std::isfinite(s[i]) || s[i] < 0 || s[i] > limits[i])
      throw InputError(fmt::format("{}[{}]: the standard deviation of {} must lie in [0, {:g}] ({} units), found {}",
                                   f.Path(kKey), i, kNames[i], limits[i], i < 4 ? "pixel" : "lens",
                                   nlohmann::json(s[i]).dump()));
    out[i] = s[i];
  }
  return out;
}

}  // namespace

KnownIntrinsics IntrinsicsFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields f(json, origin);
  KnownIntrinsics k;
  const auto size = f.Required<std::vector<int>>("image_size");
  if (size.size() != 2 || size[0] < 16 || size[1] < 16)
    throw InputError(f.Path("image_size") + ": expected [width, height]");
  k.width = size[0];
  k.height = size[1];
  k.fx = f.RequiredInRange("fx", 1, 1e5);
  k.fy = f.RequiredInRange("fy", 1, 1e5);
  k.cx = f.RequiredInRange("cx", 0, k.width);
  k.cy = f.RequiredInRange("cy", 0, k.height);
  const auto d = f.Optional<std::vector<double>>("distortion", std::vector<double>(5, 0.0));
  if (d.size() != 5) throw InputError(f.Path("distortion") + ": expected [k1, k2, p1, p2, k3]");
  // A lens term beyond 1e3 maps no image point anywhere sensible; it is a unit or typing slip.
  for (double term : d)
    if (!std::isfinite(term) || std::abs(term) > 1e3)
      throw InputError(f.Path("distortion") + ": expected finite terms within +-1000, found " +
                       nlohmann::json(term).dump());
  std::copy(d.begin(), d.end(), k.distortion.begin());
  k.stddev = StddevFromJson(f, k);
  f.RejectUnknownKeys();
  return k;
}

bool KnownIntrinsics::HasPrior() const {
  return std::any_of(stddev.begin(), stddev.end(), [](double s) { return s > 0; });
}

KnownIntrinsics CheckedIntrinsics(const KnownIntrinsics& k, const std::string& origin) {
  // JSON has no inf or NaN (they would read back as null), so name them here before the reader's rules.
  const std::pair<const char*, double> numbers[] = {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}};
  for (const auto& [field, value] : numbers)
    if (!std::isfinite(value))
      throw InputError(fmt::format("{}.{}: expected a finite number, found {}", origin, field, value));
  for (double term : k.distortion)
    if (!std::isfinite(term))
      throw InputError(fmt::format("{}.distortion: expected finite terms, found {}", origin, term));
  for (double sigma : k.stddev)
    if (!std::isfinite(sigma))
      throw InputError(
          fmt::format("{}.stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3: expected finite terms, found {}", origin, sigma));
  // The same rules the session reader applies, so a recorder never writes what its reader refuses.
  return IntrinsicsFromJson(ToJson(k), origin);
}

nlohmann::json ToJson(const KnownIntrinsics& k) {
  nlohmann::json out = {{"image_size", {k.width, k.height}}, {"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy},
                        {"distortion", k.distortion}};
  if (k.HasPrior()) out["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"] = k.stddev;
  return out;
}

nlohmann::json ToJson(const SessionManifest& m) {
  nlohmann::json recordings = nlohmann::json::array();
  for (const auto& r : m.recordings) {
    nlohmann::json entry = {{"file", r.file}, {"purpose", ToString(r.purpose)}};
    if (!r.source.empty()) entry["source"] = r.source;
    if (!r.source_path.empty()) entry["source_path"] = r.source_path;
    recordings.push_back(entry);
  }
  return {
      {"schema", kSessionSchemaName},
      {"schema_version", kSessionSchemaVersion},
      {"sensor", {{"model", m.sensor.model}, {"label", m.sensor.label}, {"serial", m.sensor.serial}}},
      {"driver", m.driver},
      {"depth_units", ToString(m.depth_units)},
      {"optics", m.optics},
      {"rig", m.rig ? nlohmann::json{{"squares", {m.rig->squares_x, m.rig->squares_y}},
                                     {"square_size_m", m.rig->square_size_m},
                                     {"outline", ToString(m.rig->outline)},
                                     {"notes", m.rig->notes}}
                    : nlohmann::json(nullptr)},
      {"notes", m.notes},
      {"cameras",
       [&] {
         nlohmann::json c = nlohmann::json::object();
         if (m.colour_intrinsics) c["colour"] = ToJson(*m.colour_intrinsics);
         if (m.depth_intrinsics) c["depth"] = ToJson(*m.depth_intrinsics);
         return c;
       }()},
      {"created_utc", m.created_utc},
      {"tool_version", m.tool_version},
      {"recordings", recordings},
  };
}

RigInfo RigFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields fields(json, origin);
  RigInfo rig;
  const auto squares = fields.Required<std::vector<int>>("squares");
  const auto within = [](int n) { return n >= kMinSquaresPerSide && n <= kMaxSquaresPerSide; };
  if (squares.size() != 2 || !within(squares[0]) || !within(squares[1])) {
    throw InputError(fields.Path("squares") + ": expected [squares_x, squares_y], each " +
                     std::to_string(kMinSquaresPerSide) + ".." + std::to_string(kMaxSquaresPerSide));
  }
  rig.squares_x = squares[0];
  rig.squares_y = squares[1];
  rig.square_size_m = fields.RequiredInRange("square_size_m", kMinSquareSizeM, kMaxSquareSizeM);
  rig.outline = ParseField(fields, "outline", BoardOutlineFromString);
  rig.notes = fields.Optional<std::string>("notes", "");
  fields.RejectUnknownKeys();
  return rig;
}

SessionManifest SessionManifestFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields fields(json, origin);
  const auto schema = fields.Required<std::string>("schema");
  if (schema != kSessionSchemaName) {
    throw InputError(fields.Path("schema") + ": expected \"" + std::string(kSessionSchemaName) + "\", found \"" +
                     schema + "\"");
  }
  SessionManifest m;
  m.schema_version = fields.Required<int>("schema_version");
  if (m.schema_version < kOldestSessionSchemaVersion || m.schema_version > kSessionSchemaVersion) {
    throw SchemaVersionError(origin + ": session schema version " + std::to_string(m.schema_version) +
                             " is not understood by this tool (it reads versions " +
                             std::to_string(kOldestSessionSchemaVersion) + " to " +
                             std::to_string(kSessionSchemaVersion) + "); upgrade speckle");
  }
  {
    JsonFields sensor(fields.RequiredValue("sensor"), fields.Path("sensor"));
    m.sensor.model = sensor.Required<std::string>("model");
    m.sensor.label = sensor.Optional<std::string>("label", "");
    m.sensor.serial = sensor.Optional<std::string>("serial", "");
    sensor.RejectUnknownKeys();
  }
  m.driver = fields.Required<std::string>("driver");
  m.depth_units = ParseField(fields, "depth_units", DepthUnitsFromString);
  m.optics = fields.Required<std::string>("optics");
  if (const auto* rig = fields.OptionalValue("rig")) m.rig = RigFromJson(*rig, fields.Path("rig"));
  m.notes = fields.Optional<std::string>("notes", "");
  if (m.schema_version >= 2) {
    if (const auto* cameras = fields.OptionalValue("cameras")) {
      JsonFields c(*cameras, fields.Path("cameras"));
      if (const auto* colour = c.OptionalValue("colour"))
        m.colour_intrinsics = IntrinsicsFromJson(*colour, c.Path("colour"));
      if (const auto* depth = c.OptionalValue("depth"))
        m.depth_intrinsics = IntrinsicsFromJson(*depth, c.Path("depth"));
      c.RejectUnknownKeys();
    }
  }
  m.created_utc = fields.Optional<std::string>("created_utc", "");
  m.tool_version = fields.Optional<std::string>("tool_version", "");
  const auto& recordings = fields.RequiredValue("recordings");
  if (!recordings.is_array()) throw InputError(fields.Path("recordings") + ": expected an array");
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    JsonFields entry(recordings[i], fields.Path("recordings") + "[" + std::to_string(i) + "]");
    RecordingEntry r;
    r.file = entry.Required<std::string>("file");
    if (r.file.empty() || r.file.find("..") != std::string::npos || r.file.front() == '/') {
      throw InputError(entry.Path("file") + ": expected a file name inside the session, found \"" + r.file + "\"");
    }
    r.purpose = ParseField(entry, "purpose", PurposeFromString);
    r.source = entry.Optional<std::string>("source", "");
    r.source_path = entry.Optional<std::string>("source_path", "");
    entry.RejectUnknownKeys();
    m.recordings.push_back(r);
  }
  fields.RejectUnknownKeys();
  return m;
}

SessionManifest ReadSessionManifest(const std::filesystem::path& session_dir) {
  const auto path = session_dir / kSessionFileName;
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": cannot open (is this a session directory?)");
  return SessionManifestFromJson(ReadJsonFile(path.string()), path.string());
}

void WriteSessionManifest(const std::filesystem::path& session_dir, const SessionManifest& manifest) {
  WriteFileAtomically(session_dir / kSessionFileName, ToJson(manifest).dump(2) + "\n");
}

}  // namespace speckle
