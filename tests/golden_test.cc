// Golden regression: the committed session tests/golden/session is
// calibrated and its artifacts are compared field by field with the
// committed goldens. Numbers must agree to a relative 1e-4 (absolute 1e-9
// near zero), a statistic of residuals (its mean, its percentiles) to 1e-4
// of its block's rms: the machine's BLAS and CPU move the artifacts by up to
// 5e-6 (the tangent fits, which stop in their valley at the solver's
// tolerance: on an AVX-512 EPYC with Debian's ATLAS, which libceres3 pulls
// in, their held-out max moved 4.9e-6, a covariance 1.1e-6, and a held-out
// mean of -8.5e-5 mm by 1e-6 mm, 2026-12-08), far below any change of
// behaviour. Strings, booleans and
// integers must agree exactly. Only clocks, creation times and paths are
// ignored; the session's path inside messages reads SESSION. The numbers of
// the diagnosis's candidate fits are only checked to be numbers: on this
// 10-frame session some candidates are ill-posed (up to 39 parameters, fits
// stopped at 30 iterations), and the last bits of a vectorized sum, which
// depend on where the allocator put the arrays, move their results by up to
// 10 %, and near-equal ones may trade places: they are compared by name,
// their names and recommendation must match, and their held-out errors
// agree within 15 %. tests/hunt_test.cc tests the
// ranking where it matters.
//
// To accept a deliberate change of results, regenerate the goldens:
//   bash scripts/regenerate-goldens.sh
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

constexpr double kRelative = 1e-4, kAbsolute = 1e-9;
constexpr double kCandidateRelative = 0.15;  // candidates' held-out errors move by up to 10 % (see above)

bool EndsWith(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}
// run_fingerprint hashes the executable, so every build has its own (its
// behaviour is Golden.ARerunWithNothingChangedWritesNoVersion's).
const std::set<std::string> kIgnored = {"created_utc",  "tool_version", "path",           "stage_seconds",
                                        "wall_seconds", "step_seconds", "run_fingerprint"};

fs::path GoldenDir() { return fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden"; }

json Stripped(json j, const std::string& session) {
  if (j.is_object()) {
    json out = json::object();
    for (auto& [key, value] : j.items())
      if (!kIgnored.count(key)) out[key] = Stripped(value, session);
    // Near-equal candidates may trade places (see above): compare them by name.
    if (out.contains("candidates") && out["candidates"].is_array()) {
      auto& c = out["candidates"];
      std::sort(c.begin(), c.end(),
                [](const json& a, const json& b) { return a.value("name", "") < b.value("name", ""); });
    }
    return out;
  }
  if (j.is_array()) {
    for (auto& v : j) v = Stripped(v, session);
  }
  if (j.is_string()) {
    std::string text = j.get<std::string>();
    for (std::size_t at; (at = text.find(session)) != std::string::npos;) text.replace(at, session.size(), "SESSION");
    return text;
  }
  return j;
}

// `scale`: the rms of the statistics block a number is in (0 elsewhere).
void Compare(const json& expected, const json& actual, const std::string& path, int* differences, double scale = 0) {
  const auto report = [&](const std::string& what) {
    if (++*differences <= 20) ADD_FAILURE() << path << ": " << what;
  };
  const bool candidate = path.find(".diagnosis.candidates[") != std::string::npos;
  if (expected.is_number_float() || (expected.is_number() && (actual.is_number_float() || candidate))) {
    if (!actual.is_number()) return report("expected a number, found " + actual.dump());
    const double e = expected.get<double>(), a = actual.get<double>();
    double relative = kRelative;
    if (candidate) {
      // Only each candidate's held-out error, loosely (see above): a fit that
      // breaks moves it by far more. Counts such as poses_better move too.
      if (!EndsWith(path, ".held_out_raw") && !EndsWith(path, ".held_out_mm")) return;
      relative = kCandidateRelative;
    }
    if (std::abs(e - a) > std::max(kAbsolute, relative * std::max(std::abs(e), scale))) {
      report("expected " + expected.dump() + ", found " + actual.dump());
    }
  } else if (expected.is_object()) {
    if (!actual.is_object()) return report("expected an object");
    const double rms = expected.contains("rms") && expected["rms"].is_number() ? expected["rms"].get<double>() : 0;
    for (const auto& [key, value] : expected.items()) {
      if (!actual.contains(key))
        report("missing key " + key);
      else
        Compare(value, actual[key], path + "." + key, differences, rms);
    }
    for (const auto& [key, value] : actual.items())
      if (!expected.contains(key)) report("unexpected new key " + key);
  } else if (expected.is_array()) {
    if (!actual.is_array() || actual.size() != expected.size()) {
      return report("expected an array of " + std::to_string(expected.size()) + ", found " +
                    actual.dump().substr(0, 80));
    }
    for (std::size_t i = 0; i < expected.size(); ++i)
      Compare(expected[i], actual[i], path + "[" + std::to_string(i) + "]", differences);
  } else if (expected != actual) {
    report("expected " + expected.dump() + ", found " + actual.dump());
  }
}

TEST(Golden, ArtifactsOfTheCommittedSessionMatch) {
  ScratchDir scratch;
  // Work on a copy: the repository's session is never written to.
  fs::copy(GoldenDir() / "session", scratch / "session", fs::copy_options::recursive);
  const auto r = RunTool("run-pipeline", (scratch / "session").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const bool regenerate = std::getenv("SPECKLE_REGENERATE_GOLDENS") != nullptr;
  for (const char* name : {"calibration.json", "report.json"}) {
    const json actual =
        Stripped(ReadJson(scratch / "session" / "calibrations" / "v0001" / name), (scratch / "session").string());
    const fs::path golden = GoldenDir() / ("expected_" + std::string(name));
    if (regenerate) {
      std::ofstream(golden) << actual.dump(1) << "\n";
      continue;
    }
    ASSERT_TRUE(fs::exists(golden)) << golden << " is missing; run scripts/regenerate-goldens.sh";
    int differences = 0;
    Compare(ReadJson(golden), actual, name, &differences);
    EXPECT_EQ(differences, 0) << name << " differs from its golden in " << differences << " place(s)";
  }
}

// A session too long to hold every frame's raw image reads them again where a
// step needs them (pipeline/raw_depth.h): the results must not change.
TEST(Golden, FramesReadAgainGiveTheSameArtifacts) {
  ScratchDir scratch;
  fs::copy(GoldenDir() / "session", scratch / "session", fs::copy_options::recursive);
  const std::string session = (scratch / "session").string();
  const auto held = RunTool("run-pipeline", session);
  ASSERT_EQ(held.exit_code, 0) << held.output;
  const auto read_again = RunTool("run-pipeline", session + " --held-raw-frames 0 --new-version");
  ASSERT_EQ(read_again.exit_code, 0) << read_again.output;
  for (const char* name : {"calibration.json", "report.json"}) {
    const auto artifact = [&](const char* version) {
      return Stripped(ReadJson(scratch / "session" / "calibrations" / version / name), session);
    };
    json first = artifact("v0001"), second = artifact("v0002");
    for (const char* key : {"history", "parent_version"}) first.erase(key), second.erase(key);
    int differences = 0;
    Compare(first, second, name, &differences);
    EXPECT_EQ(differences, 0) << name << " changed when frames were read again";
  }
}

// A rerun that would write the same numbers again (every rerun used to write
// a new 36-92 MB version) names the version it would repeat instead; any
// change to the inputs, the model or the options writes a new one.
TEST(Golden, ARerunWithNothingChangedWritesNoVersion) {
  ScratchDir scratch;
  fs::copy(GoldenDir() / "session", scratch / "session", fs::copy_options::recursive);
  const std::string session = (scratch / "session").string();
  // The separate steps, which are faster: what decides a version does not depend on how the cameras are fitted,
  // except that the choice is one of its inputs (the last run).
  const std::string separate = " --separate-cameras";
  const fs::path versions = scratch / "session" / "calibrations";
  ASSERT_EQ(RunTool("run-pipeline", session + separate).exit_code, 0);
  const auto again = RunTool("run-pipeline", session + separate + " --threads 1");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("unchanged    v0001 made it from the same inputs"), std::string::npos) << again.output;
  EXPECT_FALSE(fs::exists(versions / "v0002"));
  ASSERT_EQ(RunTool("refit", session + " --base-form tangent").exit_code, 0);
  const auto refit_again = RunTool("refit", session + " --base-form tangent --from v0001");
  EXPECT_EQ(refit_again.exit_code, 0) << refit_again.output;
  EXPECT_NE(refit_again.output.find("unchanged    v0002"), std::string::npos) << refit_again.output;
  EXPECT_FALSE(fs::exists(versions / "v0003"));
  // A refit of another parent, or with another model, is new.
  ASSERT_EQ(RunTool("refit", session + " --from v0001").exit_code, 0);
  EXPECT_TRUE(fs::exists(versions / "v0003"));
  std::ofstream(scratch / "session" / "session.json", std::ios::app) << "\n";
  const auto edited = RunTool("run-pipeline", session + separate);
  EXPECT_EQ(edited.exit_code, 0) << edited.output;
  EXPECT_TRUE(fs::exists(versions / "v0004")) << "session.json changed: " << edited.output;
  ASSERT_EQ(RunTool("run-pipeline", session + separate + " --new-version").exit_code, 0);
  EXPECT_TRUE(fs::exists(versions / "v0005"));
  EXPECT_EQ(ReadJson(versions / "v0004" / "calibration.json")["run_fingerprint"],
            ReadJson(versions / "v0005" / "calibration.json")["run_fingerprint"]);
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  EXPECT_TRUE(fs::exists(versions / "v0006")) << "the joint calibration (the default) is another run";
}

}  // namespace
}  // namespace speckle
