#pragma once
// Stage 10: where does the fitted model disagree with the measurements, and
// which physical effect is missing? Works on held-out residuals (each pose
// predicted by a fit that never saw it), treats the samples of one pose as
// correlated, and compares against the noise floor the data allow.
#include <optional>
#include <string>
#include <vector>

#include "stages/depth_model_fit.h"

namespace speckle {

struct DiagnosisOptions {
  double complete_ratio = 1.15;     // held-out RMS within this of the floor: nothing missing
  double min_reduction = 0.03;      // a candidate must cut held-out RMS by this share...
  double min_significance = 2.5;    // ...with this many standard errors over poses
  int bins = 8;
  std::size_t max_candidate_samples = 6000;  // ranking fits use an even subsample beyond this
  int folds = 5;  // pose folds of the candidates' cross-validation
};

struct NoiseFloor {
  double quantization_raw = 0;      // one raw unit / sqrt(12): a single pixel's rounding
  double repeated_frames_raw = -1;  // scatter of one board point over frames of a still pose (< 0: none)
  int repeated_groups = 0;
  double neighbour_pixels_raw = -1; // scatter between neighbouring pixels of one frame (< 0: none)
  double floor_raw = 0;             // the one used
  std::string source;               // which estimate it is
};

struct CovariateFinding {
  std::string covariate, unit;
  double explained_share = 0;  // of the excess variance over the floor, held out by pose
  double significance = 0;     // mean gain per pose over its standard error
  std::vector<double> bin_centre, bin_mean, bin_count;  // residual profile (empty for 2-D)
};

struct Candidate {
  std::string name;  // effect name, or "base_form:<form>"
  std::string doc;
  double held_out_rms = 0;  // raw units
  double held_out_mm = 0;
  double reduction = 0;     // 1 - candidate / current
  double significance = 0;  // per-pose gain in squared error, in standard errors
  bool recommended = false;
};

struct Diagnosis {
  NoiseFloor floor;
  double held_out_rms = 0, held_out_mm = 0;
  double ratio_to_floor = 0;
  bool complete = false;
  std::vector<CovariateFinding> covariates;  // most explaining first
  std::vector<Candidate> candidates;         // best first
  std::optional<std::string> recommended;    // the effect to add, if any
  std::string verdict;                       // plain language, one paragraph
};

// `session` is only used to write the command the verdict suggests.
Diagnosis RunModelDiagnosis(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                            const DepthFit& fit, const std::string& session);

}  // namespace speckle
