// record-session freenect in a build configured with -DSPECKLE_LIBFREENECT=OFF:
// no live capture, said as a missing device (exit 4) rather than a link error.
#include "recorder/sources/freenect_source.h"
#include "schemas/errors.h"

namespace speckle {

PlannedRecording PlanFreenectCapture(const FreenectCaptureOptions&, std::vector<std::string>*) {
  throw DeviceError(
      "this build has no live capture: it was configured with -DSPECKLE_LIBFREENECT=OFF (rebuild "
      "with it ON and libfreenect-dev installed, or record with libfreenect's `record` and import "
      "the dump with `record-session fakenect:DIR`)");
}

}  // namespace speckle
