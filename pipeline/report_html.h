#pragma once
// report.html: one self-contained page (Plotly from npm and the report's
// numbers inlined) that opens offline, with the plots a user needs to see
// where the model fails and how the error fell over the session's versions.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "lab/model_lab.h"

namespace speckle {

// What the plots show, from the chosen fit's held-out residuals: an even
// subsample of samples, the residual heat map over the image, and per-frame
// RMS with the worst frames.
nlohmann::json PlotDataJson(const ModelLab& lab);

// The page for a report that holds "plots", "diagnosis", "fits", "history"
// and "depth_uncertainty"; nullopt when the front-end assets are not
// installed (scripts/setup.sh installs them with npm).
std::optional<std::string> ReportHtml(const nlohmann::json& report);

}  // namespace speckle
