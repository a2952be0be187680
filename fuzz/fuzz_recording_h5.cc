// An HDF5 recording, mutated through the HDF5 API (fuzz/h5_mutation.h): the
// reader opens it, reads every frame, clock and accelerometer sample, and
// session-info's inspection runs over a session holding it.
#include <opencv2/core.hpp>

#include "fuzz/fuzz_input.h"
#include "fuzz/h5_mutation.h"
#include "recorder/recording_reader.h"
#include "recorder/recording_writer.h"
#include "recorder/session_inspection.h"

using namespace speckle;

namespace {

// A small valid recording: colour, depth and accelerometer, three frames.
std::string TemplateRecording() {
  const std::filesystem::path path = fuzz::Scratch() / "template.h5";
  std::filesystem::remove(path);
  RecordingHeader h;
  h.purpose = RecordingPurpose::kDepthboard;
  h.source = "fuzz";
  h.colour_size = cv::Size(8, 6);
  h.depth_size = cv::Size(8, 6);
  h.has_accel = true;
  {
    RecordingWriter writer(path, h);
    for (int i = 0; i < 3; ++i) {
      FramePair f;
      f.colour.image = cv::Mat(6, 8, CV_8UC3, cv::Scalar(10, 20, 30));
      f.colour.host_time_ns = f.depth.host_time_ns = 1'000'000'000LL * (i + 1);
      f.depth.image = cv::Mat(6, 8, CV_16UC1, cv::Scalar(700 + i));
      f.accel.push_back({});
      writer.Append(f);
    }
  }
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string valid = TemplateRecording();
  const std::filesystem::path session = fuzz::Scratch() / "session";
  std::filesystem::remove_all(session);
  std::filesystem::create_directories(session);
  const std::filesystem::path path = session / "depthboard.h5";
  fuzz::WriteBytes(path, valid);
  fuzz::FuzzBytes in(data, size);
  if (!fuzz::MutateH5(path.string(), in)) return 0;
  fuzz::ExpectOnlyInputErrors([&] {
    const RecordingReader reader(path);
    for (std::int64_t i = 0; i < reader.frame_count() && i < 64; ++i) (void)reader.ReadFrame(i);
    for (int stream = 0; stream < 3; ++stream) (void)reader.ReadClock(stream);
    (void)reader.ReadAccel();
  });
  fuzz::ExpectOnlyInputErrors([&] {
    SessionManifest m;
    m.driver = "fuzz";
    m.recordings = {{"depthboard.h5", RecordingPurpose::kDepthboard, "", ""}};
    WriteSessionManifest(session, m);
    (void)FormatSummary(InspectSession(session));
  });
  return 0;
}
