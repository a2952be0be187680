// A libfreenect `record` dump: the first byte chooses which file the rest
// replaces (INDEX.txt, a depth PGM, a colour PPM, an accelerometer dump,
// device.json); the other files stay valid, so the fuzzer reaches each
// reader past the ones before it.
#include "fuzz/fuzz_input.h"
#include "recorder/sources/fakenect_source.h"

using namespace speckle;

namespace {

const char* const kFiles[] = {"INDEX.txt", "d-1000.000000-1000.pgm", "r-1000.001000-1000.ppm",
                              "a-1000.002000-1000.dump", "device.json"};

void WriteValidDump(const std::filesystem::path& dir) {
  std::string depth = "P5 640 480 65535\n";
  for (int i = 0; i < 640 * 480; ++i) depth += std::string{'\xbc', '\x02'};  // 700, little-endian
  fuzz::WriteBytes(dir / kFiles[1], depth);
  fuzz::WriteBytes(dir / kFiles[2], "P6 640 480 255\n" + std::string(640 * 480 * 3, '\x40'));
  fuzz::WriteBytes(dir / kFiles[3], std::string(12, '\0'));
  fuzz::WriteBytes(dir / kFiles[4], R"({"schema_version": 1})");
  fuzz::WriteBytes(dir / kFiles[0], std::string(kFiles[1]) + "\n" + kFiles[2] + "\n" + kFiles[3] + "\n");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::filesystem::path dir = fuzz::Scratch() / "dump";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  WriteValidDump(dir);
  fuzz::WriteBytes(dir / kFiles[data[0] % 5], data + 1, size - 1);
  fuzz::ExpectOnlyInputErrors([&] {
    FakenectImportOptions options;
    options.allow_unpaired = data[0] & 0x80;
    PlannedRecording plan = PlanFakenectImport(dir, options, nullptr);
    while (plan.source->Next()) {
    }
  });
  return 0;
}
