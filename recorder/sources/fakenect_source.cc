#include "recorder/sources/fakenect_source.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "recorder/sources/pnm.h"
#include "recorder/sources/stamp_pairing.h"
#include "schemas/decimal_text.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kDepthFileBytes = 17 + 640 * 480 * 2;   // "P5 640 480 65535\n" + data
constexpr std::size_t kColourFileBytes = 15 + 640 * 480 * 3;  // "P6 640 480 255\n" + data
constexpr std::size_t kAccelFileBytes = 12;                   // freenect_raw_tilt_state

struct IndexEntry {
  char kind = 'd';
  std::int64_t host_time_ns = 0;
  std::uint64_t device_timestamp = 0;
  fs::path file;
  int line = 0;
};

// "1483969349.177955" -> ns, without going through a double. Times beyond
// the year 2262 (int64 nanoseconds) are refused, naming the line.
std::int64_t ParseSeconds(const std::string& text, const std::string& where) {
  const auto dot = text.find('.');
  constexpr std::int64_t kMaxSeconds = INT64_MAX / 1'000'000'000LL - 1;
  const auto seconds = ParseDecimal(text.substr(0, dot), kMaxSeconds);
  if (!seconds) throw InputError(where + ": time \"" + text + "\" is out of range (expected seconds since 1970)");
  std::int64_t ns = *seconds * 1'000'000'000LL;
  if (dot != std::string::npos) {
    std::string fraction = text.substr(dot + 1, 9);
    fraction.resize(9, '0');
    ns += ParseDecimal(fraction).value_or(0);
  }
  return ns;
}

std::vector<IndexEntry> ReadIndex(const fs::path& dir) {
  const fs::path index = dir / "INDEX.txt";
  std::ifstream in(index);
  if (!in) throw InputError(index.string() + ": missing (expected a libfreenect record dump with INDEX.txt)");
  static const std::regex kLine(R"(^([dra])-(\d+(?:\.\d+)?)-(\d+)\.(pgm|ppm|dump)$)");
  std::vector<IndexEntry> entries;
  std::set<std::string> listed;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::smatch m;
    const std::string where = index.string() + ":" + std::to_string(number);
    if (!std::regex_match(line, m, kLine)) {
      throw InputError(where + ": malformed entry \"" + line +
                       "\" (expected d-<time>-<timestamp>.pgm, r-<time>-<timestamp>.ppm or a-<time>-<timestamp>.dump)");
    }
    const char kind = m[1].str()[0];
    const std::string ext = m[4];
    if ((kind == 'd' && ext != "pgm") || (kind == 'r' && ext != "ppm") || (kind == 'a' && ext != "dump")) {
      throw InputError(where + ": entry \"" + line + "\" has the wrong extension for its kind");
    }
    const auto timestamp = ParseDecimal(m[3].str());
    if (!timestamp) throw InputError(where + ": device timestamp " + m[3].str() + " is out of range");
    if (!listed.insert(line).second) throw InputError(where + ": entry \"" + line + "\" is listed twice");
    IndexEntry e{kind, ParseSeconds(m[2], where), static_cast<std::uint64_t>(*timestamp), dir / line, number};
    std::error_code ec;
    const auto size = fs::file_size(e.file, ec);
    if (ec) throw InputError(where + ": listed file " + e.file.string() + " is missing");
    const std::size_t expected = kind == 'd' ? kDepthFileBytes : kind == 'r' ? kColourFileBytes : kAccelFileBytes;
    if (size != expected) {
      throw InputError(e.file.string() + ": " + std::to_string(size) + " bytes, expected " + std::to_string(expected) +
                       (size < expected ? " (truncated)" : ""));
    }
    entries.push_back(std::move(e));
  }
  return entries;
}

AccelSample ReadAccel(const IndexEntry& e) {
  std::ifstream in(e.file, std::ios::binary);
  unsigned char b[12] = {};
  in.read(reinterpret_cast<char*>(b), 12);
  const auto i16 = [&](int o) { return static_cast<std::int16_t>(b[o] | (b[o + 1] << 8)); };
  AccelSample a;
  a.host_time_ns = e.host_time_ns;
  a.device_timestamp = e.device_timestamp;
  a.counts = {i16(0), i16(2), i16(4)};
  a.tilt_angle = static_cast<std::int8_t>(b[6]);
  a.tilt_status = static_cast<std::int8_t>(b[8]);
  return a;
}

struct PlannedPair {
  const IndexEntry* depth = nullptr;
  const IndexEntry* colour = nullptr;
  std::int64_t time_ns = 0;
  std::vector<AccelSample> accel;
};

class FakenectSource : public FrameSource {
 public:
  FakenectSource(std::vector<IndexEntry> entries, std::vector<PlannedPair> pairs)
      : entries_(std::move(entries)), pairs_(std::move(pairs)) {}
  std::int64_t expected_frames() const override { return static_cast<std::int64_t>(pairs_.size()); }
  std::optional<FramePair> Next() override {
    if (next_ >= pairs_.size()) return std::nullopt;
    const PlannedPair& p = pairs_[next_];
    FramePair frame;
    frame.source_number = static_cast<std::int64_t>(next_);
    ++next_;
    if (p.depth) {
      frame.depth.image = ReadPgm16(p.depth->file, ByteOrder::kLittleEndian, {{640, 480}, {65535}});
      frame.depth.device_timestamp = p.depth->device_timestamp;
      frame.depth.host_time_ns = p.depth->host_time_ns;
    }
    if (p.colour) {
      frame.colour.image = ReadPpm8(p.colour->file, {{640, 480}, {255}});
      frame.colour.device_timestamp = p.colour->device_timestamp;
      frame.colour.host_time_ns = p.colour->host_time_ns;
    }
    frame.accel = p.accel;
    return frame;
  }

 private:
  std::vector<IndexEntry> entries_;  // owns what pairs_ points to
  std::vector<PlannedPair> pairs_;
  std::size_t next_ = 0;
};

}  // namespace

PlannedRecording PlanFakenectImport(const fs::path& dump_dir, const FakenectImportOptions& options,
                                    std::vector<std::string>* notes) {
  if (!fs::is_directory(dump_dir)) throw InputError(dump_dir.string() + ": not a directory (expected a fakenect dump)");
  std::vector<IndexEntry> entries = ReadIndex(dump_dir);
  std::vector<const IndexEntry*> depth, colour, accel;
  for (const auto& e : entries) (e.kind == 'd' ? depth : e.kind == 'r' ? colour : accel).push_back(&e);
  const auto by_time = [](const IndexEntry* a, const IndexEntry* b) { return a->host_time_ns < b->host_time_ns; };
  std::stable_sort(colour.begin(), colour.end(), by_time);
  std::stable_sort(accel.begin(), accel.end(), by_time);
  const fs::path index = dump_dir / "INDEX.txt";
  if (depth.empty() && colour.empty()) {
    throw InputError(index.string() + ": lists no depth (d-) or colour (r-) frames; the dump is empty");
  }

  // Each frame with its partner of the other stream by host time: the
  // closest pairs within the gap first, as every import pairs them.
  std::vector<std::int64_t> depth_ns, colour_ns;
  for (const IndexEntry* d : depth) depth_ns.push_back(d->host_time_ns);
  for (const IndexEntry* c : colour) colour_ns.push_back(c->host_time_ns);
  std::vector<PlannedPair> pairs;
  for (const StampPair& s : PairByStamp(depth_ns, colour_ns, static_cast<std::int64_t>(options.max_pair_gap_s * 1e9)))
    pairs.push_back(
        {s.depth >= 0 ? depth[s.depth] : nullptr, s.colour >= 0 ? colour[s.colour] : nullptr, s.time_ns, {}});

  if (!depth.empty() && !colour.empty()) {
    std::vector<std::string> unpaired;
    for (const auto& p : pairs)
      if (!p.depth || !p.colour) unpaired.push_back((p.depth ? p.depth : p.colour)->file.filename().string());
    if (!unpaired.empty()) {
      const std::string message = std::to_string(unpaired.size()) + " frame(s) have no partner within " +
                                  std::to_string(options.max_pair_gap_s * 1000) + " ms, first " + unpaired.front();
      if (!options.allow_unpaired) {
        throw InputError(index.string() + ": " + message +
                         " (use --allow-unpaired to keep them as single-stream frames)");
      }
      if (notes) notes->push_back(message + "; kept as single-stream frames");
    }
  } else if (notes) {
    notes->push_back(std::string("the dump holds ") + (depth.empty() ? "colour" : "depth") + " frames only");
  }

  // Accelerometer samples ride with the first pair at or after them.
  std::size_t next_pair = 0;
  for (const IndexEntry* a : accel) {
    while (next_pair + 1 < pairs.size() && pairs[next_pair].time_ns < a->host_time_ns) ++next_pair;
    pairs[next_pair].accel.push_back(ReadAccel(*a));
  }

  PlannedRecording planned;
  planned.file = ToString(options.purpose) + ".h5";
  RecordingHeader& h = planned.header;
  h.purpose = options.purpose;
  h.source = "fakenect";
  h.source_path = fs::absolute(dump_dir).string();
  if (!depth.empty()) h.depth_size = cv::Size(640, 480);
  if (!colour.empty()) h.colour_size = cv::Size(640, 480);
  h.depth_units = DepthUnits::kRaw11Bit;
  h.has_accel = !accel.empty();
  const fs::path device_json = dump_dir / "device.json";
  if (fs::exists(device_json)) {
    h.device_registration_json = ReadJsonFile(device_json.string()).dump();
  }
  planned.source = std::make_unique<FakenectSource>(std::move(entries), std::move(pairs));
  return planned;
}

}  // namespace speckle
