#include "apps/sources/source_kind.h"

#include <CLI/Error.hpp>
#include <algorithm>

namespace speckle {
namespace {

// "sim, freenect, fakenect:DIR, frames:DIR, tum:DIR or rosbag:FILE".
std::string SourceAlternatives() {
  const auto kinds = SourceKinds();
  std::string text;
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == kinds.size() ? " or " : ", ") + SourceSyntax(kinds[i]);
  }
  return text;
}

}  // namespace

std::string SourceSyntax(const SourceKind& kind) {
  return kind.path ? std::string(kind.name) + ":" + kind.path : std::string(kind.name);
}

std::string SourceChoices() {
  std::string text;
  for (const SourceKind& kind : SourceKinds()) text += (text.empty() ? "" : " | ") + SourceSyntax(kind);
  return text;
}

std::string SourceDescriptions() {
  std::size_t width = 0;
  for (const SourceKind& kind : SourceKinds()) width = std::max(width, SourceSyntax(kind).size());
  std::string text;
  for (const SourceKind& kind : SourceKinds()) {
    const std::string syntax = SourceSyntax(kind);
    text += (text.empty() ? "  " : "\n  ") + syntax + std::string(width + 2 - syntax.size(), ' ') + kind.description;
  }
  return text;
}

SessionPlan PlanSource(const std::string& source, const SourceFlags& flags, const SessionManifest& base) {
  const auto colon = source.find(':');
  const std::string name = source.substr(0, colon);
  const std::string path = colon == std::string::npos ? "" : source.substr(colon + 1);
  const auto kinds = SourceKinds();
  const auto kind = std::find_if(kinds.begin(), kinds.end(), [&](const SourceKind& k) { return k.name == name; });
  if (kind == kinds.end() || (kind->path != nullptr) == path.empty()) {
    throw CLI::ValidationError("SOURCE", "expected " + SourceAlternatives() + ", found \"" + source + "\"");
  }
  // Checked here, before anything is read, rather than left unused.
  if (flags.seed && name != "sim") throw CLI::ValidationError("--seed", "only the simulator (SOURCE sim) has a seed");
  SessionPlan plan;
  plan.manifest = base;
  kind->plan(flags, path, plan);
  return plan;
}

}  // namespace speckle
