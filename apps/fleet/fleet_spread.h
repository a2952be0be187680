#pragma once
// The cross-unit check: a unit whose parameter lies outside the rest of the
// fleet's spread, beyond what its own sigma explains, is flagged by name.
#include <string>
#include <vector>

#include "apps/fleet/fleet_unit.h"

namespace speckle::fleet {

struct SpreadOptions {
  // The chance that a fleet of units alike has any unit's parameter flagged:
  // one fleet in ten. Split over the units and the parameters compared.
  double fleet_false_alarm = 0.1;
  int min_other_units = 4;  // fewer others have no spread worth the name
};

struct OutOfSpread {
  std::string serial, parameter;
  double value = 0, fleet_mean = 0, fleet_spread = 0, sigma = 0, z = 0, threshold = 0;
};

// Each calibrated unit against the others (leave-one-out, so that it does
// not widen the spread it is judged by), as a prediction of where a new unit
// of their make would lie: their mean, known to s^2/n, plus the make's own
// spread tau^2 = max(0, s^2 - their mean sigma^2) (what their scatter holds
// beyond their calibrations' uncertainty), plus the unit's own sigma^2:
// z = (value - mean) / sqrt(s^2/n + tau^2 + sigma^2), s the others'
// standard deviation. Flagged beyond Student's t (n - 1 degrees of freedom) at
// fleet_false_alarm split over units and parameters. Only parameters every
// calibrated unit has.
std::vector<OutOfSpread> FindOutOfSpread(const std::vector<UnitRecord>& units, const SpreadOptions& options = {});

// Two-sided: the t beyond which a Student's t variable with `dof` degrees of
// freedom lies with probability `alpha`.
double StudentTQuantile(double alpha, double dof);

}  // namespace speckle::fleet
