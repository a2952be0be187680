#include "apps/given_camera.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <sstream>

#include "formats/camera_file.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

std::array<double, 9> ParseSigma(const std::string& text, const std::string& flag) {
  std::array<double, 9> sigma{};
  std::istringstream in(text);
  std::string item;
  std::size_t n = 0;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || n >= sigma.size() || !(value >= 0))
      throw UsageError(
          fmt::format("{} {}: expected 4 or 9 standard deviations, each 0 or more: fx,fy,cx,cy (px), "
                      "then k1,k2,p1,p2,k3",
                      flag, text));
    sigma[n++] = value;
  }
  if (n != 4 && n != 9)
    throw UsageError(
        fmt::format("{} {}: {} values; expected 4 (fx,fy,cx,cy in px; the lens then held as the file "
                    "gives it) or 9 (then k1,k2,p1,p2,k3)",
                    flag, text, n));
  return sigma;
}

}  // namespace

std::optional<KnownIntrinsics> GivenCamera(const GivenCameraFlags& flags, const std::string& camera) {
  const std::string flag = "--" + camera + "-camera";
  if (flags.file.empty()) {
    if (!flags.sigma.empty() || flags.exact)
      throw UsageError(fmt::format("{}-sigma / {}-exact need {} FILE", flag, flag, flag));
    return std::nullopt;
  }
  if (!flags.sigma.empty() && flags.exact)
    throw UsageError(fmt::format("{} {}: give {}-sigma or {}-exact, not both", flag, flags.file, flag, flag));
  formats::CameraFile read = formats::ReadCameraFile(flags.file);
  KnownIntrinsics& k = read.intrinsics;
  if (!flags.sigma.empty()) {
    k.stddev = ParseSigma(flags.sigma, flag + "-sigma");
  } else if (flags.exact) {
    k.stddev = {};
  } else if (!read.has_stddev) {
    throw InputError(fmt::format(
        "{} {}: the file ({}) gives no standard deviations, and without them the camera would be taken as exact. "
        "Give them, e.g. {}-sigma 2,2,2,2 (fx,fy,cx,cy in px; add k1,k2,p1,p2,k3 to free the lens within theirs), "
        "or say {}-exact",
        flag, flags.file, read.format, flag, flag));
  }
  k = CheckedIntrinsics(k, flag + " " + flags.file);
  spdlog::info("{} camera from {} ({}): fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}, {}", camera, flags.file, read.format,
               k.fx, k.fy, k.cx, k.cy,
               k.HasPrior() ? fmt::format("a prior of sigma {} (fx fy cx cy k1 k2 p1 p2 k3)", fmt::join(k.stddev, " "))
                            : std::string("taken as exact"));
  return k;
}

void CheckCameraFitsImages(const KnownIntrinsics& k, const std::string& camera, const std::string& given_by,
                           const SessionPlan& plan) {
  for (const PlannedRecording& r : plan.recordings) {
    const auto& size = camera == "colour" ? r.header.colour_size : r.header.depth_size;
    if (size && (size->width != k.width || size->height != k.height))
      throw InputError(fmt::format("the {} camera given ({}) is for {}x{} images, but {} holds {}x{} {} images", camera,
                                   given_by, k.width, k.height, r.file, size->width, size->height, camera));
  }
}

}  // namespace speckle
