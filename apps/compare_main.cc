// compare A B: how two depth calibrations differ over the image, against
// their own stated uncertainty (issue 48). A and B are sessions (their
// newest version), version folders or calibration.json files: two versions
// of one session, two sessions of one sensor, or two sensors.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/calibration_comparison.h"
#include "apps/cli_main.h"
#include "apps/depth_sigmas.h"
#include "apps/map_legend.h"
#include "model/depth_model.h"
#include "schemas/artifact_schema.h"
#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace {

using namespace speckle;
namespace fs = std::filesystem;

struct Flags {
  std::string a, b, out;
  std::vector<double> depths_m = ComparisonOptions{}.depths_m;
  bool json = false;
};

// `count` numbers, a null read as 0 (an unidentified parameter's covariance is written as null); throws
// InputError naming `where` for anything else.
std::vector<double> NumbersOrNull(const nlohmann::json& value, std::size_t count, const std::string& where) {
  std::vector<double> out;
  if (value.is_array())
    for (const auto& v : value) {
      if (!v.is_null() && !(v.is_number() && std::isfinite(v.get<double>()))) break;
      out.push_back(v.is_null() ? 0.0 : v.get<double>());
    }
  if (!value.is_array() || out.size() != count || value.size() != count)
    throw InputError(fmt::format("{}: expected {} numbers, found {}", where, count, value.dump().substr(0, 60)));
  return out;
}

ComparedCalibration Load(const std::string& given) {
  const fs::path file = CalibrationFile(given);
  ComparedCalibration out{apply::LoadDepthCalibration(file), DepthSigmasOf(file)};
  // The depth camera's stated covariance, or its sigmas, and the model's (the apply library carries none).
  nlohmann::json json = ReadJsonFile(file);
  const std::string where = file.string() + ": ";
  const nlohmann::json& depth = json["cameras"]["depth"];
  const nlohmann::json covariance = depth.value("covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3", nlohmann::json());
  if (!covariance.is_null()) {
    const auto values = NumbersOrNull(covariance, 81, where + "cameras.depth.covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3");
    std::copy(values.begin(), values.end(), out.camera_covariance.begin());
  } else {
    const auto sigma = NumbersOrNull(depth.value("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3", nlohmann::json()), 9,
                                     where + "cameras.depth.stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3");
    for (std::size_t i = 0; i < 9; ++i) out.camera_covariance[10 * i] = sigma[i] * sigma[i];
  }
  // The model's covariance: a row of its flat parameters' count each (model_sigma_shape.h).
  const nlohmann::json model_covariance = json["model"].value("covariance", nlohmann::json());
  const std::size_t parameters = out.calibration.model->Flat().size();
  if (!model_covariance.is_null()) {
    if (!model_covariance.is_array() || model_covariance.size() != parameters)
      throw InputError(fmt::format("{}model.covariance: expected {} rows, one per model parameter", where, parameters));
    for (std::size_t i = 0; i < parameters; ++i) {
      const auto row = NumbersOrNull(model_covariance[i], parameters, fmt::format("{}model.covariance[{}]", where, i));
      out.model_covariance.insert(out.model_covariance.end(), row.begin(), row.end());
    }
  }
  return out;
}

std::string Row(const DepthComparison& c, const ComparisonOptions& options) {
  if (c.pixels == 0)
    return fmt::format("depth {:.2f} m: no pixel has a point under both (A reads no raw value as it)\n", c.depth_m);
  const bool sigma = std::isfinite(c.sigma_a_m + c.sigma_b_m);
  return fmt::format(
      "depth {:.2f} m (raw {:.0f}): B - A in depth {:+.1f} mm (median); the points 95 % within {:.1f} mm, largest "
      "{:.1f} mm at pixel ({}, {}); {}\n",
      c.depth_m, c.raw, 1e3 * c.median_depth_difference_m, 1e3 * c.p95_abs_difference_m, 1e3 * c.max_abs_difference_m,
      c.max_u, c.max_v,
      sigma ? fmt::format(
                  "depth sigma A {:.1f} + B {:.1f} mm{}; of the pixels {:.1f} % beyond sigma A + sigma B, "
                  "{:.1f} % beyond {:g} sigma of their difference{}",
                  1e3 * c.sigma_a_m, 1e3 * c.sigma_b_m, c.extrapolated ? " (extrapolated: no boards there)" : "",
                  100 * c.share_beyond_sigma, 100 * c.share_differing, options.differ_sigmas,
                  // "most in the ..." of a share that prints as 0.0 % would point at nothing.
                  c.worst_region == "nowhere" || 100 * c.share_beyond_sigma < 0.05 ? ""
                                                                                   : ", most in the " + c.worst_region)
            : std::string("no sigma to judge it by (a report.json states none)"));
}

// The rule, said with the verdict: why the sum is drawn and the difference's own sigma judged.
std::string Rule(const ComparisonOptions& options) {
  return fmt::format(
      "rule         a depth differs where more than {:.0f} % of its pixels' points lie further apart than {:g} "
      "sigma of their difference, sqrt(sigma A^2 + sigma B^2): by chance {:.2f} % of the time for honest sigmas; "
      "the maps draw the distance over sigma A + sigma B, as mrcal does, which honest sigmas exceed 16-32 % of the "
      "time\n",
      100 * options.differ_share, options.differ_sigmas, 100 * std::erfc(options.differ_sigmas / std::sqrt(2.0)));
}

std::string Verdict(const std::vector<DepthComparison>& rows, const ComparisonOptions& options) {
  const DepthComparison* worst = nullptr;
  for (const auto& r : rows) {
    if (r.pixels == 0) return fmt::format("cannot be judged at {:.2f} m: A gives no raw value that depth", r.depth_m);
    if (!std::isfinite(r.share_differing)) return "cannot be judged: a calibration's report.json states no depth sigma";
    if (!worst || r.share_differing > worst->share_differing) worst = &r;
  }
  if (!worst) return "nothing compared";
  if (!worst->Differs(options.differ_share))
    return fmt::format(
        "the same within their uncertainty: at every depth at most {:.0f} % of the pixels' points lie "
        "further apart than {:g} sigma of their difference (at most {:.1f} %, at {:.2f} m)",
        100 * options.differ_share, options.differ_sigmas, 100 * worst->share_differing, worst->depth_m);
  return fmt::format(
      "differ: at {:.2f} m the points lie up to {:.1f} mm ({:.2f} %) apart, {:.1f} % of the pixels "
      "beyond {:g} sigma of their difference (in depth {:.1f} mm), most in the {} of the image",
      worst->depth_m, 1e3 * worst->max_abs_difference_m, 100 * worst->max_abs_difference_m / worst->depth_m,
      100 * worst->share_differing, options.differ_sigmas,
      1e3 * options.differ_sigmas * std::hypot(worst->sigma_a_m, worst->sigma_b_m), worst->worst_region);
}

nlohmann::json ToJson(const DepthComparison& c, const std::string& map) {
  const auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  return {{"depth_m", c.depth_m},
          {"raw", c.raw},
          {"pixels", c.pixels},
          {"median_depth_difference_m", c.median_depth_difference_m},
          {"p95_abs_difference_m", c.p95_abs_difference_m},
          {"max_abs_difference_m", c.max_abs_difference_m},
          {"max_pixel", {c.max_u, c.max_v}},
          {"sigma_a_m", number(c.sigma_a_m)},
          {"sigma_b_m", number(c.sigma_b_m)},
          {"extrapolated", c.extrapolated},
          {"share_beyond_sigma", number(c.share_beyond_sigma)},
          {"share_differing", number(c.share_differing)},
          {"worst_region", c.worst_region},
          {"map", map}};
}

// |B - A| / (sigma A + sigma B) as a colour map: 0 dark, 1 (the sigma) mid, 3 and beyond bright; no depth black.
void WriteMap(const DepthComparison& c, const fs::path& file) {
  cv::Mat grey(c.height, c.width, CV_8UC1);
  for (int p = 0; p < c.width * c.height; ++p)
    grey.data[p] = std::isfinite(c.ratio[static_cast<std::size_t>(p)])
                       ? static_cast<std::uint8_t>(std::lround(1 + 254 * std::min(1.0f, c.ratio[p] / 3.0f)))
                       : 0;
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_VIRIDIS);
  colour.setTo(cv::Scalar(0, 0, 0), grey == 0);
  cv::Mat ramp(1, 255, CV_8UC1);
  for (int i = 0; i < 255; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(1 + i);
  MapLegend legend{cv::Mat(), "0", "1.5 sigma", "3 sigma and beyond",
                   fmt::format("|B - A| at {:.2f} m over sigma A + sigma B; black: no depth there", c.depth_m)};
  cv::applyColorMap(ramp, legend.bar, cv::COLORMAP_VIRIDIS);
  errno = 0;
  if (!cv::imwrite(file.string(), WithLegend(colour, legend))) throw WriteFailure(file, errno);
}

void WriteFolder(const Flags& flags, const ComparedCalibration& a, const ComparedCalibration& b,
                 const std::vector<DepthComparison>& rows, const ComparisonOptions& options,
                 const std::string& verdict) {
  const fs::path out = NormalizeOutPath(flags.out, "--out");
  RemoveStaleStaging(fs::absolute(out).parent_path());
  if (fs::exists(out)) throw InputError(out.string() + ": exists; compare overwrites nothing, choose a new --out");
  WriteFolderAside(
      PartialPathFor(fs::absolute(out)),
      [&](const fs::path& staging) {
        nlohmann::json j = {
            {"schema", "speckle.comparison"},
            {"schema_version", kComparisonSchemaVersion},
            {"tool_version", kToolVersion},
            {"created_utc", UtcNowIso8601()},
            {"a", a.calibration.file.string()},
            {"b", b.calibration.file.string()},
            {"depths", nlohmann::json::array()},
            {"verdict", verdict},
            {"rule", {{"differ_sigmas", options.differ_sigmas}, {"differ_share", options.differ_share}}}};
        for (const auto& r : rows) {
          const std::string map = fmt::format("difference_over_sigma_{:.2f}m.png", r.depth_m);
          WriteMap(r, staging / map);
          j["depths"].push_back(ToJson(r, map));
        }
        std::ofstream(staging / "comparison.json") << j.dump(2) << "\n";
      },
      [&](const fs::path& staging) { return RenameInto(staging, out); });
  spdlog::info("maps and comparison.json in {}", out.string());
}

int Run(const Flags& flags) {
  if (!flags.out.empty() && fs::exists(NormalizeOutPath(flags.out, "--out")))
    throw InputError(flags.out + ": exists; compare overwrites nothing, choose a new --out");
  const ComparedCalibration a = Load(flags.a), b = Load(flags.b);
  ComparisonOptions options;
  options.depths_m = flags.depths_m;
  const std::vector<DepthComparison> rows = CompareCalibrations(a, b, options);
  const std::string verdict = Verdict(rows, options);
  std::cout << fmt::format("compare      A {} ({})\n             B {} ({})\n", a.calibration.file.string(),
                           a.calibration.model->Definition().Describe(), b.calibration.file.string(),
                           b.calibration.model->Definition().Describe())
            << "             at each depth the raw value A reads as it (its median over the image), and the point each "
               "makes of that reading at every pixel\n";
  for (const auto& r : rows) std::cout << "             " << Row(r, options);
  std::cout << Rule(options) << "verdict      " << verdict << "\n";
  if (!flags.out.empty()) WriteFolder(flags, a, b, rows, options, verdict);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Compare two depth calibrations over the image against their stated uncertainty."};
  Flags flags;
  app.add_option("A", flags.a, "session (its newest version), version folder or calibration.json")->required();
  app.add_option("B", flags.b, "the other, likewise")->required();
  app.add_option("--depths", flags.depths_m, "depths (m) to compare at")
      ->delimiter(',')
      ->capture_default_str()
      ->check(CLI::Range(0.2, 20.0).description("depths in metres, 0.2 to 20"));
  app.add_option("--out", flags.out, "folder to create with comparison.json and a map per depth");
  return RunCli("compare", app, argc, argv, [&] { return Run(flags); });
}
