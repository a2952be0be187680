#include "apps/fleet/fleet_report.h"

#include <fmt/format.h>

#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/html_text.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace speckle::fleet {
namespace fs = std::filesystem;
namespace {

std::string FlagsOf(const Summary& s, const std::string& serial) {
  std::string out;
  for (const auto& f : s.out_of_spread)
    if (f.serial == serial) out += (out.empty() ? "" : "; ") + fmt::format("{} {:+.1f} sigma", f.parameter, f.z);
  return out;
}

nlohmann::json ToJson(const Summary& s) {
  nlohmann::json units = nlohmann::json::array(), flags = nlohmann::json::array();
  for (const auto& u : s.units) units.push_back(fleet::ToJson(u));
  for (const auto& f : s.out_of_spread)
    flags.push_back({{"serial", f.serial},
                     {"parameter", f.parameter},
                     {"value", f.value},
                     {"fleet_mean", f.fleet_mean},
                     {"fleet_spread", f.fleet_spread},
                     {"sigma", f.sigma},
                     {"z", f.z},
                     {"threshold", f.threshold}});
  return {
      {"schema", "speckle.fleet"},
      {"schema_version", kFleetSchemaVersion},
      {"tool_version", kToolVersion},
      {"engine", s.engine},
      {"seconds", s.seconds},
      {"units", units},
      {"out_of_spread", flags},
      {"rule", fmt::format("a unit's parameter is out of the fleet's spread when |value - mean of the other n units| "
                           "> t x sqrt(s^2/n + tau^2 + its sigma^2): s the others' standard deviation, tau^2 = "
                           "max(0, s^2 - their mean sigma^2) the make's own spread, t Student's (n - 1 degrees "
                           "of freedom) at {} a fleet split over units and parameters; n >= {}",
                           s.spread.fleet_false_alarm, s.spread.min_other_units)}};
}

std::string Csv(const Summary& s) {
  const auto quoted = [](std::string t) {
    std::string out = "\"";
    for (char c : t) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
  };
  std::string out =
      "serial,calibrated,model,held_out_to_floor,depth_sigma_mm_at_1m,conclusion,check,out_of_spread,version,"
      "reason\n";
  for (const auto& u : s.units)
    out += fmt::format("{},{},{},{:.4f},{:.3f},{},{},{},{},{}\n", quoted(u.serial), u.calibrated ? "yes" : "no",
                       quoted(u.model), u.held_out_to_floor, u.depth_sigma_mm_at_1m, quoted(u.conclusion),
                       quoted(u.check_status), quoted(FlagsOf(s, u.serial)), quoted(u.version), quoted(u.reason));
  return out;
}

std::string Html(const Summary& s) {
  std::string html = fmt::format(
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>Speckle fleet</title><style>"
      "td,th{{padding:2px 8px;border-bottom:1px solid #ccc;text-align:left}}.flag{{color:#b00;font-weight:bold}}"
      "</style></head><body><h1>Fleet: {} units</h1><p>engine {}, {:.0f} s; {}</p><table><tr><th>serial</th>"
      "<th>calibrated</th><th>model</th><th>held-out / floor</th><th>depth sigma at 1 m (mm)</th><th>conclusion"
      "</th><th>check</th><th>out of the fleet's spread</th></tr>\n",
      s.units.size(), HtmlEscape(s.engine), s.seconds, HtmlEscape(ToJson(s)["rule"].get<std::string>()));
  for (const auto& u : s.units)
    html += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.2f}</td><td>{}</td><td{}>{}</td>"
        "<td class=\"flag\">{}</td></tr>\n",
        HtmlEscape(u.serial), u.calibrated ? "yes" : "no: " + HtmlEscape(u.reason), HtmlEscape(u.model),
        u.held_out_to_floor, u.depth_sigma_mm_at_1m, HtmlEscape(u.conclusion),
        CheckPassedOrNotAsked(u) ? "" : " class=\"flag\"", HtmlEscape(u.check_status),
        HtmlEscape(FlagsOf(s, u.serial)));
  return html + "</table></body></html>\n";
}

fs::path NextSummaryFolder(const fs::path& fleet) {
  for (int n = 1;; ++n) {
    const fs::path p = fleet / fmt::format("summary-{:04d}", n);
    if (!fs::exists(p)) return p;
  }
}

}  // namespace

std::string TerminalTable(const Summary& s) {
  std::string out = fmt::format("{:<12} {:<11} {:<22} {:>10} {:>12}  {:<13} {}\n", "unit", "calibrated", "model",
                                "held/floor", "sigma 1 m", "check", "conclusion; out of the fleet's spread");
  for (const auto& u : s.units) {
    const std::string flags = FlagsOf(s, u.serial);
    out += u.calibrated ? fmt::format("{:<12} {:<11} {:<22} {:>10.2f} {:>9.2f} mm  {:<13} {}{}\n", u.serial, "yes",
                                      u.model, u.held_out_to_floor, u.depth_sigma_mm_at_1m, u.check_status,
                                      u.conclusion, flags.empty() ? "" : "; OUT OF SPREAD: " + flags)
                        : fmt::format("{:<12} {:<11} {}\n", u.serial, "FAILED", u.reason);
  }
  return out;
}

fs::path WriteSummary(const fs::path& fleet, const Summary& s) {
  const fs::path target = NextSummaryFolder(fleet);
  return WriteFolderAside(
      PartialPathFor(fs::absolute(target)),
      [&](const fs::path& staging) {
        WriteFileAtomically(staging / "fleet.json", ToJson(s).dump(1) + "\n");
        WriteFileAtomically(staging / "fleet.csv", Csv(s));
        WriteFileAtomically(staging / "fleet.html", Html(s));
      },
      [&](const fs::path& staging) { return RenameInto(staging, fs::absolute(target)); });
}

}  // namespace speckle::fleet
