#include "pipeline/report_html.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace speckle {
namespace {

std::optional<std::string> ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void Replace(std::string& text, const std::string& placeholder, const std::string& value) {
  const std::size_t at = text.find(placeholder);
  if (at != std::string::npos) text.replace(at, placeholder.size(), value);
}

}  // namespace

nlohmann::json PlotDataJson(const ModelLab& lab) {
  const DepthFit& fit = lab.Chosen().fit;
  const std::vector<PairedSample>& samples = lab.ChosenSamples();
  const model::DepthModel m = fit.Model();
  constexpr std::size_t kPoints = 2000;
  const std::size_t stride = std::max<std::size_t>(1, samples.size() / kPoints);
  nlohmann::json plots;
  std::vector<double> raw, truth, modelled, residual, time;
  double low = 1e9, high = -1e9;
  for (std::size_t i = 0; i < samples.size(); i += stride) {
    if (!std::isfinite(fit.held_out_residual_raw[i])) continue;
    raw.push_back(samples[i].raw);
    truth.push_back(samples[i].depth_m);
    modelled.push_back(m.Depth(CovariatesOf(samples[i])));
    residual.push_back(fit.held_out_residual_raw[i]);
    time.push_back(samples[i].time_s);
    low = std::min(low, samples[i].depth_m), high = std::max(high, samples[i].depth_m);
  }
  plots["raw"] = raw;
  plots["true_depth_m"] = truth;
  plots["model_depth_m"] = modelled;
  plots["residual_raw"] = residual;
  // Frames without times (a toolbox frame folder has none) all read 0 s: a
  // column of points at 0 would look like a measurement.
  const bool timed =
      !time.empty() && *std::max_element(time.begin(), time.end()) > *std::min_element(time.begin(), time.end());
  plots["time_s"] = timed ? nlohmann::json(time) : nlohmann::json(nullptr);
  plots["depth_range"] = {low, high};
  // Mean held-out residual in 20 x 15 cells of the depth image.
  constexpr int kNu = 20, kNv = 15;
  std::vector<double> sum(kNu * kNv, 0.0), count(kNu * kNv, 0.0);
  std::map<int, std::pair<double, int>> by_frame;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double r = fit.held_out_residual_raw[i];
    if (!std::isfinite(r)) continue;
    const int cu = std::clamp(static_cast<int>(samples[i].u / 640 * kNu), 0, kNu - 1);
    const int cv = std::clamp(static_cast<int>(samples[i].v / 480 * kNv), 0, kNv - 1);
    sum[cv * kNu + cu] += r, count[cv * kNu + cu] += 1;
    by_frame[samples[i].frame].first += r * r;
    by_frame[samples[i].frame].second += 1;
  }
  nlohmann::json rows = nlohmann::json::array(), u_centres = nlohmann::json::array(),
                 v_centres = nlohmann::json::array();
  for (int v = 0; v < kNv; ++v) {
    nlohmann::json row = nlohmann::json::array();
    for (int u = 0; u < kNu; ++u) {
      const int k = v * kNu + u;
      row.push_back(count[k] > 0 ? nlohmann::json(sum[k] / count[k]) : nlohmann::json(nullptr));
    }
    rows.push_back(row);
    v_centres.push_back((v + 0.5) * 480.0 / kNv);
  }
  for (int u = 0; u < kNu; ++u) u_centres.push_back((u + 0.5) * 640.0 / kNu);
  plots["heat_map"] = {{"mean_residual_raw", rows}, {"u_centres", u_centres}, {"v_centres", v_centres}};
  std::vector<int> frames;
  std::vector<double> rms;
  std::vector<std::tuple<double, int, int>> worst;
  for (const auto& [frame, sq] : by_frame) {
    frames.push_back(frame);
    rms.push_back(std::sqrt(sq.first / sq.second));
    worst.emplace_back(rms.back(), frame, sq.second);
  }
  std::sort(worst.rbegin(), worst.rend());
  nlohmann::json worst_json = nlohmann::json::array();
  for (std::size_t k = 0; k < worst.size() && k < 10; ++k)
    worst_json.push_back(
        {{"frame", std::get<1>(worst[k])}, {"rms_raw", std::get<0>(worst[k])}, {"samples", std::get<2>(worst[k])}});
  plots["frames"] = {{"frame", frames}, {"rms_raw", rms}};
  plots["worst_frames"] = worst_json;
  return plots;
}

std::optional<std::string> ReportHtml(const nlohmann::json& report) {
  const std::filesystem::path assets(SPECKLE_REPORT_ASSETS_DIR);
  auto page = ReadText(assets / "template.html");
  const auto plotly = ReadText(assets / "node_modules" / "plotly.js-dist-min" / "plotly.min.js");
  if (!page || !plotly) return std::nullopt;
  // The page reads no covariance matrix: a pattern version's two (770 x 770
  // each) were 23 of its 28 MB. report.json keeps them.
  nlohmann::json shown = report;
  if (shown.contains("fits") && shown["fits"].is_array())
    for (auto& fit : shown["fits"]) fit.erase("covariance");
  std::string data = shown.dump();
  // Inside <script>, "</" could close the element early and "<!--" starts
  // HTML's escaped script state, in which the page's own "</script>" no
  // longer ends it (a formula effect named "<!--<script>" blanked the page).
  // In JSON, '<' stands only inside strings, where \u003c reads the same.
  for (std::size_t at = 0; (at = data.find('<', at)) != std::string::npos; at += 6) data.replace(at, 1, "\\u003c");
  Replace(*page, "/*PLOTLY_JS*/", *plotly);
  Replace(*page, "/*REPORT_JSON*/", data);
  return page;
}

}  // namespace speckle
