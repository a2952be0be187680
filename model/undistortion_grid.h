#pragma once
// The undistortion grid g(r, x, y) -> r' (thesis chapter 4): the raw value a
// flat wall would read, per image cell and raw value. stages/undistortion_grid.h
// builds it; the depth model applies it before the base form and the effects.
#include <cstdint>
#include <string>
#include <vector>

namespace speckle {

// How each planar snapshot's true raw value was estimated.
enum class TrueRawMethod { kImageMinimum, kHyperboloid, kCentreMinimum, kOwnPlane };
const char* ToString(TrueRawMethod method);

// Grid nodes closer than this (raw units) are below the sensor's resolution
// (one raw step), and would make apply tabulate millions of knots.
inline constexpr double kMinNodeSpacingRaw = 1.0;
inline constexpr int kMaxGridCells = 4096;  // per axis
inline constexpr int kMaxGridNodes = 4096;  // raw nodes

struct UndistortionGrid {
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;  // normalized coordinates covered
  int nx = 0, ny = 0;
  std::vector<double> raw_nodes;  // increasing
  // [raw node][y cell][x cell], row-major: the correction r' - r.
  std::vector<float> correction;
  std::vector<float> std_error;
  std::vector<std::uint8_t> supported;
  TrueRawMethod method = TrueRawMethod::kHyperboloid;  // the one used (see max_square_tilt_deg)
  double max_tilt_deg = 0;                             // the most tilted wall's tilt

  std::size_t Index(int k, int j, int i) const { return (static_cast<std::size_t>(k) * ny + j) * nx + i; }
  // r' for a raw value seen at normalized (x, y): trilinear, clamped.
  double Apply(double raw, double x, double y) const;
  // The standard error of Apply's correction there: cells are estimated from
  // different pixels (independent), while one cell's raw nodes interpolate
  // the same walls (taken as fully correlated).
  double StdErrorAt(double raw, double x, double y) const;
  // Share of nodes inside the region of support.
  double SupportedShare() const;
  // What makes the grid unusable, naming the field (empty when it is sound):
  // a finite extent with min < max; 1 to kMaxGridCells cells along x and y;
  // at least two finite raw nodes, increasing by at least kMinNodeSpacingRaw;
  // correction, std_error and supported of nodes x ny x nx finite values.
  std::string Problem() const;
};

}  // namespace speckle
