#pragma once
// Tests whose independent units are board poses, not samples. A user's
// session has 15-25 poses; every sample of one pose shares its pose error and,
// for a depth-dependent effect, one offset. Tests over samples then count
// thousands of correlated values as evidence, and standard errors over poses
// of a heavy-tailed gain (one far pose gaining much, the rest a little) have
// almost no power. Rank tests over poses have both: validity from the sign
// flips of exchangeable poses, and power from consistency across poses.
#include <cstdint>
#include <map>
#include <vector>

namespace speckle {

// One-sided exact Wilcoxon signed-rank test that the differences tend to be
// positive: the share of the 2^n sign flips of the ranked |differences|
// whose positive rank sum is at least the observed one. Zeros are dropped,
// ties take their mean rank. 1 when fewer than one difference is left.
double SignedRankPValue(const std::vector<double>& differences);

// The fewest of n poses that must gain (those with the largest gains, the
// others losing) for SignedRankPValue to reach p_max; n + 1 when even all n
// gaining does not. What the test can detect at this many poses.
int PosesNeededToGain(int n, double p_max);

// Does a profile of per-pose values against a per-pose covariate predict
// the poses it did not see? Poses are sorted by the covariate into `bins`
// groups of neighbours; each pose's value is predicted by the mean of the
// other poses in its group; the statistic is the squared error this removes,
// sum(y^2 - (y - prediction)^2). The p value is the share of `permutations`
// random reassignments of the values to the poses (seeded: reproducible)
// with a statistic at least as large.
struct ProfileTest {
  double gain = 0;         // the statistic, in the values' squared units
  double chance_gain = 0;  // its mean over the permutations: what chance alone explains
  double p_value = 1;
  std::vector<double> prediction;  // per pose, held out
};
ProfileTest PoseProfileTest(const std::vector<double>& covariate, const std::vector<double>& value, int bins,
                            int permutations = 1999, std::uint64_t seed = 18);

// The same question for a step with a common slope: a step between poses
// (a firmware table's seam) is one the profile's groups of neighbours
// straddle, and a fitted base form leaves it as a Z (the slope it takes up,
// and the jump). The statistic is the squares the best such step explains,
// the split searched with at least 3 poses a side; the permutations search
// theirs too, so the p value pays for the search, and gain - chance_gain is
// what the step explains beyond what a search finds in noise. Not held out:
// a pose next to the step cannot tell from the others which side it is on,
// and that cost alone drowned a step plainly there. `prediction` stays zero.
ProfileTest PoseStepTest(const std::vector<double>& covariate, const std::vector<double>& value,
                         int permutations = 1999, std::uint64_t seed = 18);

// How much a candidate's share of RMS removed (1 - sqrt(sum with / sum
// without), over each pose's squared residuals without and with it) could
// move with other poses of the same kind: the 5th and 95th percentiles over
// `resamples` bootstrap draws of the poses (seeded: reproducible). Both 0
// for fewer than 3 poses.
struct ReductionInterval {
  double low = 0, high = 0;
};
ReductionInterval PoseBootstrapReduction(const std::vector<std::pair<double, double>>& squares_without_with,
                                         int resamples = 999, std::uint64_t seed = 18);

// The mean per-pose gain over its standard error (0 for fewer than 3 poses):
// a z-like score whose units are poses, not samples.
double MeanGainSignificance(const std::map<int, double>& gain_by_pose);

}  // namespace speckle
