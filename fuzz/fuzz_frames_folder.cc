// A folder of frames (NNNN-d.pgm depth, NNNN-c1.jpg / .png colour): the first
// byte chooses which file the rest replaces; the other stays valid.
#include <opencv2/imgcodecs.hpp>

#include "fuzz/fuzz_input.h"
#include "recorder/sources/frames_dir_source.h"

using namespace speckle;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const std::string depth = [] {
    std::string pgm = "P5 640 480 2047\n";
    for (int i = 0; i < 640 * 480; ++i) pgm += std::string{'\x02', '\xbc'};  // 700, big-endian
    return pgm;
  }();
  static const std::string colour = [] {
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 90, 120)), jpeg);
    return std::string(jpeg.begin(), jpeg.end());
  }();
  const std::filesystem::path dir = fuzz::Scratch() / "frames";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const int which = data[0] % 3;
  fuzz::WriteBytes(dir / "0000-d.pgm", depth);
  fuzz::WriteBytes(dir / "0000-c1.jpg", colour);
  const char* const names[] = {"0000-d.pgm", "0000-c1.jpg", "0001-c1.png"};
  if (which == 2) fuzz::WriteBytes(dir / "0001-d.pgm", depth);
  fuzz::WriteBytes(dir / names[which], data + 1, size - 1);
  fuzz::ExpectOnlyInputErrors([&] {
    for (PlannedRecording& plan : PlanFramesImport(dir, FramesImportOptions{}, nullptr))
      while (plan.source->Next()) {
      }
  });
  return 0;
}
