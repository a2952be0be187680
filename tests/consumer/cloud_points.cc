// cloud_points CALIBRATION RAW_VALUE: applies a calibration to a frame whose
// every pixel reads RAW_VALUE and prints the points and their mean depth,
// then the colour pixels its depth registered to the colour camera reaches.
#include <apply/depth_corrector.h>
#include <apply/registered_depth.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const speckle::apply::DepthCalibration calibration = speckle::apply::LoadDepthCalibration(argv[1]);
  const speckle::apply::DepthCorrector corrector(calibration);
  std::vector<std::uint16_t> raw(static_cast<std::size_t>(corrector.Width()) * corrector.Height(),
                                 static_cast<std::uint16_t>(std::atoi(argv[2])));
  const speckle::apply::OrganizedCloud cloud = corrector.Cloud(raw, 0);
  int points = 0;
  double z = 0;
  for (std::size_t p = 2; p < cloud.xyz.size(); p += 3)
    if (std::isfinite(cloud.xyz[p])) ++points, z += cloud.xyz[p];
  int registered = 0;
  for (float d : speckle::apply::RegisteredDepth(cloud, calibration)) registered += std::isfinite(d);
  std::printf("%d points, mean depth %.4f m, %d registered pixels\n", points, points ? z / points : 0.0, registered);
  return 0;
}
