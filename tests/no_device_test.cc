// Live capture with no Kinect attached: exit 4 with a message that says so,
// and nothing written.
#include <gtest/gtest.h>

#include "schemas/errors.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

TEST(LiveCapture, NoDeviceExitsWithClearMessage) {
  ScratchDir s;
  fs::create_directories(s / "out");
  const auto r = RunTool("record-session", "freenect --duration 1 --out " + (s / "out" / "s").string());
  EXPECT_EQ(r.exit_code, kExitNoDevice) << r.output;
  EXPECT_NE(r.output.find("Kinect"), std::string::npos) << r.output;
}

// The IR step opens the IR camera: the user is told to cover the projector
// before the device is looked for.
TEST(LiveCapture, IrStepWithoutDeviceSaysToCoverTheProjectorThenExits4) {
  ScratchDir s;
  const auto r = RunTool("record-session", "freenect --purpose ir_chessboard --out " + (s / "s").string());
  EXPECT_EQ(r.exit_code, kExitNoDevice) << r.output;
  EXPECT_NE(r.output.find("cover the IR projector"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no Kinect found"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(s / "s")) << "nothing is written without a device";
}

}  // namespace
}  // namespace speckle
