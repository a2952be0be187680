#pragma once
// A calibrated camera from the file another tool wrote, as the session's
// known intrinsics (schemas/session_manifest.h), so a calibration the user
// already has enters as a prior instead of being typed into JSON:
//  - ROS camera_info YAML (camera_calibration_parsers; the calibrator's
//    ost.yaml), distortion model plumb_bob;
//  - OpenCV FileStorage YAML or XML (cv::FileStorage): camera_matrix,
//    cameraMatrix or K; distortion_coefficients, dist_coeffs, distCoeffs or
//    D; image_width and image_height, or image_size / imageSize; and, when
//    present, std_deviations_intrinsics (cv::calibrateCamera's
//    stdDeviationsIntrinsics: fx fy cx cy k1 k2 p1 p2 k3 ...);
//  - mrcal .cameramodel: LENSMODEL_PINHOLE, LENSMODEL_OPENCV4 or LENSMODEL_OPENCV5;
//  - Kalibr camchain.yaml: "FILE#cam1" picks a camera (the only one when
//    there is one); camera_model pinhole with distortion radtan or none.
// Only Brown-Conrady lenses (k1 k2 p1 p2 k3) are read: another model (a
// fisheye, a rational or an equidistant one) is refused by name, since
// dropping its terms would give a wrong camera. Throws InputError naming
// the file and the field.
#include <string>

#include "schemas/session_manifest.h"

namespace speckle::formats {

struct CameraFile {
  KnownIntrinsics intrinsics;  // stddev as the file gives it (zero when it gives none)
  std::string format;          // "ROS camera_info", "OpenCV FileStorage", "mrcal", "Kalibr camchain"
  bool has_stddev = false;
};

// `spec`: a file, or "FILE#camN" for a Kalibr camchain's camera N.
CameraFile ReadCameraFile(const std::string& spec);

}  // namespace speckle::formats
