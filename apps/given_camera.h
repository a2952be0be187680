#pragma once
// record-session's --colour-camera / --depth-camera: a calibration the user
// already has (formats/camera_file.h) as the session's known intrinsics,
// with its standard deviations from the file or from --*-camera-sigma, so
// that it enters the calibration as a prior; exact only when asked
// (--*-camera-exact). Throws InputError naming the flag and the file.
#include <optional>
#include <string>

#include "recorder/frame_source.h"

namespace speckle {

struct GivenCameraFlags {
  std::string file;   // FILE or FILE#camN; empty: none given
  std::string sigma;  // "fx,fy,cx,cy[,k1,k2,p1,p2,k3]"
  bool exact = false;
};

// `camera`: "colour" or "depth", as the flags name it.
std::optional<KnownIntrinsics> GivenCamera(const GivenCameraFlags& flags, const std::string& camera);

// The camera's image size against every planned recording's images of that camera.
void CheckCameraFitsImages(const KnownIntrinsics& intrinsics, const std::string& camera, const std::string& given_by,
                           const SessionPlan& plan);

}  // namespace speckle
