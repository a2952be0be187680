#include "recorder/manifest_agreement.h"

#include <fmt/format.h>

#include "schemas/errors.h"

namespace speckle {

std::vector<std::string> ManifestDisagreements(const RecordingEntry& entry, const RecordingHeader& h,
                                               const SessionManifest& manifest) {
  std::vector<std::string> out;
  if (h.purpose != entry.purpose) {
    out.push_back(fmt::format("{}: purpose is {} in the file but {} in session.json", entry.file, ToString(h.purpose),
                              ToString(entry.purpose)));
  }
  if (!entry.source.empty() && (entry.source != h.source || entry.source_path != h.source_path)) {
    out.push_back(fmt::format("{}: came from {} {} by the file but {} {} by session.json", entry.file, h.source,
                              h.source_path, entry.source, entry.source_path));
  }
  if (h.depth_size && h.depth_units != manifest.depth_units) {
    out.push_back(fmt::format("{}: depth units {} differ from session.json's {}", entry.file, ToString(h.depth_units),
                              ToString(manifest.depth_units)));
  }
  // Cameras given for another image size (issue 47: session-info said
  // "valid: yes", and only apply-calibration refused the calibration made).
  const auto size_differs = [&](const std::optional<KnownIntrinsics>& k, const std::optional<cv::Size>& size,
                                const char* camera) {
    if (!k || !size || (k->width == size->width && k->height == size->height)) return;
    out.push_back(fmt::format("{}: its {} images are {}x{}, but session.json's cameras.{} is for {}x{} images",
                              entry.file, camera, size->width, size->height, camera, k->width, k->height));
  };
  size_differs(manifest.colour_intrinsics, h.colour_size, "colour");
  size_differs(manifest.depth_intrinsics, h.depth_size, "depth");
  return out;
}

void RefuseManifestDisagreements(const std::filesystem::path& session_dir, const RecordingEntry& entry,
                                 const RecordingHeader& header, const SessionManifest& manifest) {
  const std::vector<std::string> problems = ManifestDisagreements(entry, header, manifest);
  if (problems.empty()) return;
  std::string text = (session_dir / kSessionFileName).string() + " and its recording disagree:";
  for (const std::string& p : problems) text += "\n  " + p;
  throw InputError(text + "\n(session-info lists every such problem)");
}

}  // namespace speckle
