// Every hand-written JSON the tools read: the first byte chooses the reader
// (session.json, a model spec with formula effects, a scenario, a
// calibration.json), the rest is the file.
#include "apply/depth_calibration.h"
#include "fuzz/fuzz_input.h"
#include "lab/model_spec.h"
#include "schemas/json_fields.h"
#include "schemas/session_manifest.h"
#include "simulator/scenario.h"
#include "simulator/scenario_usability.h"

using namespace speckle;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  fuzz::ExpectOnlyInputErrors([&] {
    switch (data[0] % 4) {
      case 0: {
        const SessionManifest m = SessionManifestFromJson(ParseJsonText(text, "session.json"), "session.json");
        (void)ToJson(m).dump();
        break;
      }
      case 1: {
        const ModelSpec spec = ModelSpecFromJson(ParseJsonText(text, "model.json"), "model.json");
        const model::DepthModel model(spec.Definition());
        model::Covariates c;
        c.raw = 700;
        (void)model.Depth(c);
        break;
      }
      case 2: {
        const sim::Scenario scenario = sim::ScenarioFromJson(ParseJsonText(text, "scenario.json"), "scenario.json");
        sim::CheckUsable(scenario, "scenario.json");  // the check record-session runs next
        (void)sim::ToJson(scenario).dump();
        break;
      }
      case 3: {
        const std::filesystem::path file = fuzz::Scratch() / "calibration.json";
        fuzz::WriteBytes(file, text);
        (void)apply::LoadDepthCalibration(file);
        break;
      }
    }
  });
  return 0;
}
