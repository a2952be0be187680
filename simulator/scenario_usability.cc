#include "simulator/scenario_usability.h"

#include <fmt/format.h>

#include <cmath>

#include "schemas/errors.h"
#include "simulator/session_simulator.h"

namespace speckle::sim {
namespace {

// A camera the simulator can render and a calibration can recover: focal
// lengths of real lenses at VGA (the wide adapter's are about 360 px), the
// principal point inside the image, distortion a Brown-Conrady lens has.
void CheckCamera(const CameraModel& c, const std::string& key) {
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  if (!in(c.fx, 100, 5000) || !in(c.fy, 100, 5000))
    throw InputError(fmt::format("{}.intrinsics: focal lengths {} and {} px; a camera at {}x{} has 100-5000", key, c.fx,
                                 c.fy, c.size.width, c.size.height));
  if (!in(c.cx, 0, c.size.width) || !in(c.cy, 0, c.size.height))
    throw InputError(fmt::format("{}.intrinsics: principal point ({}, {}) lies outside the {}x{} image", key, c.cx,
                                 c.cy, c.size.width, c.size.height));
  const auto& d = c.distortion;
  if (!(std::abs(d[0]) <= 5 && std::abs(d[1]) <= 50 && std::abs(d[4]) <= 500 && std::abs(d[2]) <= 0.2 &&
        std::abs(d[3]) <= 0.2))
    throw InputError(
        fmt::format("{}.distortion: [{}, {}, {}, {}, {}] is no lens's (|k1| <= 5, |k2| <= 50, "
                    "|k3| <= 500, |p1|, |p2| <= 0.2)",
                    key, d[0], d[1], d[2], d[3], d[4]));
}

// Whether the sensor gives a reading at true depth z (effects aside): the
// renderer's rules for the near limit, the raw range and millimetres.
bool ReadsAt(const DepthFormation& f, double z) {
  if (z < f.min_depth_m) return false;
  const double raw = std::round(f.RawFromDepth(z));
  if (!std::isfinite(raw) || raw < 0 || raw > f.max_raw) return false;
  if (!f.millimetre) return true;
  const double mm = std::round(1000 * (f.DepthFromRaw(raw) - f.mm_offset_m) / f.mm_gain);
  return mm >= 1 && mm <= 65535;
}

// What recording `what` at depths lo..hi (the keys `keys`) gets from the
// depth model: refused when no depth in the range gives a reading.
void CheckReadings(const DepthFormation& f, double lo, double hi, const std::string& what, const std::string& keys) {
  constexpr int kSteps = 64;
  for (int i = 0; i <= kSteps; ++i)
    if (ReadsAt(f, lo + (hi - lo) * i / kSteps)) return;
  throw InputError(
      fmt::format("{} at {}-{} m ({}) gets no depth reading: depth_model gives raw {:.0f}-{:.0f} there "
                  "(readings need raw 0-{} and depth beyond min_depth_m {} m)",
                  what, lo, hi, keys, f.RawFromDepth(lo), f.RawFromDepth(hi), f.max_raw, f.min_depth_m));
}

}  // namespace

void CheckUsable(const Scenario& s, const std::string& origin) {
  try {
    if (s.depthboard.poses == 0 && s.planar.snapshots == 0 && s.ir_chessboard.poses == 0)
      throw InputError("records nothing: depthboard.poses, planar.snapshots and ir_chessboard.poses are all 0");
    const SensorOptics optics = OpticsFor(s);
    CheckCamera(optics.colour, "cameras.colour");
    CheckCamera(optics.ir, "cameras.ir");
    if (s.depthboard.poses > 0) {
      CheckReadings(s.depth, s.depthboard.min_depth_m, s.depthboard.max_depth_m, "the board",
                    "depthboard.min_depth_m..max_depth_m");
      const double square_px = optics.colour.fx * s.rig.square_size_m / s.depthboard.max_depth_m;
      if (square_px < kMinSquarePx)
        throw InputError(
            fmt::format("rig.square_size_m: squares of {} m are {:.1f} px in the colour image at "
                        "depthboard.max_depth_m {} m; a chessboard detector needs {} px or more",
                        s.rig.square_size_m, square_px, s.depthboard.max_depth_m, kMinSquarePx));
    }
    if (s.planar.snapshots > 0)
      CheckReadings(s.depth, s.planar.min_depth_m, s.planar.max_depth_m, "the wall", "planar.min_depth_m..max_depth_m");
  } catch (const InputError& e) {
    throw InputError(origin + ": " + e.what());
  }
}

}  // namespace speckle::sim
