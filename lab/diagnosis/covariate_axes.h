#pragma once
// The covariates the diagnosis plots held-out residuals against: one table
// (kCovariateAxes in covariate_axes.cc), which the profiles, the verdict's
// "which covariate reads it" and its formula hint all read.
//
// To add a covariate (a new quantity an effect may read and the diagnosis
// plots residuals against):
//  1. model/covariates.h: a field of Covariates and its line in
//     kCovariateFields: the formula effects' variable of that name and its
//     usual range, where a formula's linearity and finiteness are checked
//     (the array's size goes up by one).
//  2. stages/records.h: the same field of PairedSample, set where samples
//     are made: stages/pairing.cc (outline sessions) and
//     stages/board_plane.cc (boards larger than their chessboard), or in a
//     pass over them as stages/raw_rate.cc is. Its value in CovariatesOf
//     (lab/fit/fit_samples.cc), by name.
//  3. Applying a calibration: apply/depth_corrector.cc (PixelCovariates)
//     gives each pixel its covariates; a covariate it leaves at 0 is applied
//     as 0, silently wrong for a formula that reads it.
//  4. pipeline/samples_file.cc: its column in kColumns with the schema
//     version it appears in (`since`), kSamplesSchemaVersion one up
//     (schemas/artifact_schema.h) and a line in schemas/CHANGES.md, so that
//     refit reads older samples with the column's default.
//  5. Here: its line in kCovariateAxes: the axis name the verdict prints,
//     its unit, the sample value, the formula variables whose effects it
//     shows, and the one-parameter formula the verdict suggests along it.
//  6. The formula variables listed in docs/extending.md and
//     docs/conventions.md; `clang-format -i` what you touched; the goldens
//     (report.json lists every axis) again with scripts/regenerate-goldens.sh;
//     `cd build && ctest -L fast`.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "stages/records.h"

namespace speckle {

struct CovariateAxis {
  const char* name;  // as the verdict and report.json name it: "image x"
  const char* unit;
  std::function<double(const PairedSample&)> value;
  std::function<double(const PairedSample&)> second;  // set for 2-D axes
  // The Covariates variables (model/covariates.h) an effect reads for its
  // error to show along this axis: an effect reading "x" shows along
  // "image x", "image position" and "image radius".
  std::vector<std::string> shown_by;
  // A formula effect along this axis, for the verdict's hint when no
  // catalogue effect explains it: its name, formula ("{level}" stands for
  // the raw level of the best step the samples show) and parameters with
  // their units.
  struct FormulaHint {
    const char* name;
    const char* formula;
    std::vector<std::pair<const char*, const char*>> parameters;  // name, unit
  } hint;
  bool pose_level = false;  // a pose mostly has one value of it: tested by pose means too
};

const std::vector<CovariateAxis>& CovariateAxes();

// The axis of that name, or null.
const CovariateAxis* FindCovariateAxis(const std::string& name);

}  // namespace speckle
