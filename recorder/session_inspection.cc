#include "recorder/session_inspection.h"

#include <fmt/format.h>

#include <algorithm>

#include "recorder/manifest_agreement.h"
#include "recorder/progress.h"
#include "recorder/recording_reader.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

// The code point of a Unicode direction control at text[i] (U+200E-200F,
// U+202A-202E, U+2066-2069, all E2 8x xx in UTF-8), else 0.
unsigned DirectionControl(std::string_view text, std::size_t i) {
  if (i + 2 >= text.size() || static_cast<unsigned char>(text[i]) != 0xE2) return 0;
  const auto second = static_cast<unsigned char>(text[i + 1]), third = static_cast<unsigned char>(text[i + 2]);
  if ((second != 0x80 && second != 0x81) || (third & 0xC0u) != 0x80) return 0;
  const unsigned point = 0x2000u + ((second & 0x3Fu) << 6) + (third & 0x3Fu);
  const bool control = point == 0x200E || point == 0x200F || (point >= 0x202A && point <= 0x202E) ||
                       (point >= 0x2066 && point <= 0x2069);
  return control ? point : 0;
}

// A string from a file as a terminal may show it: control characters
// (C0, DEL and UTF-8's C1) as \xNN, so session.json cannot clear the screen,
// recolour it or forge a line such as "valid: yes"; and direction controls
// as \uNNNN, so a label cannot reverse what follows it on the line.
std::string Shown(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    const bool c1 = c == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
                    static_cast<unsigned char>(text[i + 1]) <= 0x9F;
    if (const unsigned point = DirectionControl(text, i)) {
      out += fmt::format("\\u{:04x}", point);
      i += 2;
    } else if (c < 0x20 || c == 0x7F) {
      out += fmt::format("\\x{:02x}", c);
    } else if (c1) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[++i]));
    } else {
      out += text[i];
    }
  }
  return out;
}

std::string SizeText(const std::optional<cv::Size>& size) {
  return size ? fmt::format("{}x{}", size->width, size->height) : "";
}

// Every frame read as run-pipeline reads it: a damaged chunk is a problem
// here too (run-pipeline skips such frames). Empty when all are readable.
std::string UnreadableFrames(const RecordingReader& reader, const std::string& file) {
  Progress progress("session-info: " + file, reader.frame_count());
  std::int64_t unreadable = 0;
  std::string first;
  for (std::int64_t i = 0; i < reader.frame_count(); ++i) {
    progress.Update(i + 1);
    try {
      reader.ReadFrame(i);
    } catch (const InputError& e) {
      if (unreadable++ == 0) first = e.what();
    }
  }
  progress.Finish();
  if (!unreadable) return "";
  return fmt::format("{}: {} of {} frames unreadable (run-pipeline skips them); the first: {}", file, unreadable,
                     reader.frame_count(), first);
}

}  // namespace

double HostTimeSpanS(const RecordingReader& reader) {
  std::int64_t first = 0, last = 0;
  bool any = false;
  for (int stream = 0; stream < 3; ++stream) {
    const auto clock = reader.ReadClock(stream);
    for (std::size_t i = 0; i < clock.valid.size(); ++i) {
      if (!clock.valid[i] || clock.host_time_ns[i] == 0) continue;
      first = any ? std::min(first, clock.host_time_ns[i]) : clock.host_time_ns[i];
      last = any ? std::max(last, clock.host_time_ns[i]) : clock.host_time_ns[i];
      any = true;
    }
  }
  // In double: a damaged clock can hold INT64_MIN and INT64_MAX (found by fuzz_recording_h5).
  return (static_cast<double>(last) - static_cast<double>(first)) * 1e-9;
}

std::string ImpossibleTimes(const RecordingReader& reader, const std::string& file) {
  constexpr double kLongestRecordingS = 86400;
  static constexpr const char* kStream[] = {"colour", "depth", "ir"};
  for (int stream = 0; stream < 3; ++stream) {
    const auto clock = reader.ReadClock(stream);
    for (std::size_t i = 0; i < clock.valid.size(); ++i) {
      if (clock.valid[i] && clock.host_time_ns[i] < 0)
        return fmt::format("{}: frame {}'s {} host time is before 1970 ({} ns)", file, i, kStream[stream],
                           clock.host_time_ns[i]);
    }
  }
  if (const double span = HostTimeSpanS(reader); span > kLongestRecordingS)
    return fmt::format("{}: its host times span {:.0f} s, more than a day; a session lasts minutes", file, span);
  return "";
}

SessionSummary InspectSession(const std::filesystem::path& session_dir) {
  SessionSummary summary;
  summary.manifest = ReadSessionManifest(session_dir);
  if (summary.manifest.recordings.empty()) summary.problems.push_back("session.json lists no recordings");
  for (const auto& entry : summary.manifest.recordings) {
    RecordingSummary r;
    r.file = entry.file;
    r.purpose = entry.purpose;
    bool opened = false;
    try {
      const RecordingReader reader(session_dir / entry.file);
      opened = true;
      const RecordingHeader& h = reader.header();
      r.source = h.source;
      r.source_path = h.source_path;
      r.frames = reader.frame_count();
      r.colour_size = SizeText(h.colour_size);
      r.depth_size = SizeText(h.depth_size);
      r.ir_size = SizeText(h.ir_size);
      r.depth_units = h.depth_size ? ToString(h.depth_units) : "";
      r.has_truth = !h.scenario_json.empty();
      r.has_device_registration = !h.device_registration_json.empty();
      r.closed_cleanly = reader.closed_cleanly();
      r.note = reader.truncation_note();
      r.accel_samples = static_cast<std::int64_t>(reader.ReadAccel().size());
      for (int stream = 0; stream < 3; ++stream) {
        const auto clock = reader.ReadClock(stream);
        const auto valid = std::count(clock.valid.begin(), clock.valid.end(), 1);
        (stream == 0 ? r.colour_frames : stream == 1 ? r.depth_frames : r.ir_frames) = valid;
      }
      r.time_span_s = HostTimeSpanS(reader);
      for (std::string& p : ManifestDisagreements(entry, h, summary.manifest)) summary.problems.push_back(std::move(p));
      if (const std::string times = ImpossibleTimes(reader, entry.file); !times.empty())
        summary.problems.push_back(times);
      if (const std::string damaged = UnreadableFrames(reader, entry.file); !damaged.empty())
        summary.problems.push_back(damaged);
      if (!reader.closed_cleanly()) {
        summary.problems.push_back(
            fmt::format("{}: the recorder did not close it (killed?); it holds {} frames up to its last flush. "
                        "`h5clear -s {}` marks it closed for tools that refuse it",
                        entry.file, r.frames, (session_dir / entry.file).string()));
      }
    } catch (const InputError& e) {
      summary.problems.push_back(e.what());
      if (!opened) r.unreadable = e.what();
    }
    summary.recordings.push_back(r);
  }
  return summary;
}

nlohmann::json ToJson(const SessionSummary& s) {
  nlohmann::json recordings = nlohmann::json::array();
  for (const auto& r : s.recordings) {
    recordings.push_back({{"file", r.file},
                          {"purpose", ToString(r.purpose)},
                          {"source", r.source},
                          {"source_path", r.source_path},
                          {"frames", r.frames},
                          {"colour_frames", r.colour_frames},
                          {"depth_frames", r.depth_frames},
                          {"ir_frames", r.ir_frames},
                          {"colour_size", r.colour_size},
                          {"depth_size", r.depth_size},
                          {"ir_size", r.ir_size},
                          {"depth_units", r.depth_units},
                          {"time_span_s", r.time_span_s},
                          {"accel_samples", r.accel_samples},
                          {"has_truth", r.has_truth},
                          {"has_device_registration", r.has_device_registration},
                          {"closed_cleanly", r.closed_cleanly},
                          {"note", r.note},
                          {"unreadable", r.unreadable}});
  }
  return {{"manifest", ToJson(s.manifest)},
          {"recordings", recordings},
          {"problems", s.problems},
          {"valid", s.problems.empty()}};
}

std::string FormatSummary(const SessionSummary& s) {
  const SessionManifest& m = s.manifest;
  // Label and serial only when the session has them (imports often do not).
  std::string sensor = Shown(m.sensor.model);
  if (!m.sensor.label.empty()) sensor += fmt::format(" \"{}\"", Shown(m.sensor.label));
  if (!m.sensor.serial.empty()) sensor += " serial " + Shown(m.sensor.serial);
  std::string out = fmt::format("sensor      {}\ndriver      {}\noptics      {}\ndepth units {}\n", sensor,
                                Shown(m.driver), Shown(m.optics), ToString(m.depth_units));
  if (m.rig) {
    out += fmt::format("rig         {}x{} squares of {:.1f} mm, outline {}\n", m.rig->squares_x, m.rig->squares_y,
                       m.rig->square_size_m * 1000, ToString(m.rig->outline));
  } else {
    out += "rig         none\n";
  }
  for (const auto& r : s.recordings) {
    if (!r.unreadable.empty()) {  // no counts to show: zeros would read as an empty recording
      out += fmt::format("\n{} ({})\n  unreadable  {}\n", Shown(r.file), ToString(r.purpose), Shown(r.unreadable));
      continue;
    }
    out += fmt::format("\n{} ({}, from {})\n  frames      {} (colour {}, depth {}, ir {})\n", Shown(r.file),
                       ToString(r.purpose), r.source.empty() ? "?" : Shown(r.source), r.frames, r.colour_frames,
                       r.depth_frames, r.ir_frames);
    if (!r.source_path.empty()) out += fmt::format("  source      {}\n", Shown(r.source_path));
    if (!r.colour_size.empty()) out += fmt::format("  colour      {}\n", r.colour_size);
    if (!r.depth_size.empty()) out += fmt::format("  depth       {} {}\n", r.depth_size, r.depth_units);
    out += fmt::format("  time span   {:.2f} s\n", r.time_span_s);
    if (r.accel_samples) out += fmt::format("  accel       {} samples\n", r.accel_samples);
    if (r.has_device_registration) out += "  device      registration constants (device.json)\n";
    if (r.has_truth) out += "  truth       simulator ground truth\n";
    if (!r.note.empty()) out += fmt::format("  note        {}\n", Shown(r.note));
  }
  out += s.problems.empty() ? "\nvalid: yes\n" : "\nvalid: NO\n";
  for (const auto& p : s.problems) out += "  problem: " + Shown(p) + "\n";
  return out;
}

}  // namespace speckle
