// The fleet's cross-unit rule (apps/fleet/fleet_spread.h) on made-up units:
// Student's t quantiles against the published table, a unit far outside
// alike units named with its parameter, a spread the make really has (tau)
// not flagged, and a unit's own large sigma excusing it.
#include <gtest/gtest.h>

#include "apps/fleet/fleet_spread.h"

namespace speckle::fleet {
namespace {

UnitRecord Unit(const std::string& serial, double b, double b_sigma, double fx = 580) {
  UnitRecord u;
  u.serial = serial, u.calibrated = true;
  u.parameters = {{"model.b", b, b_sigma}, {"depth.fx", fx, 1.0}};
  return u;
}

TEST(FleetSpread, StudentsTQuantilesAreThePublishedOnes) {
  EXPECT_NEAR(StudentTQuantile(0.05, 1), 12.706, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.05, 10), 2.228, 1e-3);
  EXPECT_NEAR(StudentTQuantile(0.0027, 6), 4.904, 2e-3);
  EXPECT_NEAR(StudentTQuantile(0.001, 30), 3.646, 2e-3);
}

TEST(FleetSpread, AUnitFarOutsideAlikeUnitsIsNamedWithItsParameter) {
  std::vector<UnitRecord> fleet;
  const double b[] = {3.010, 3.020, 3.005, 3.015, 3.012, 3.018, 3.008};
  for (int i = 0; i < 7; ++i) fleet.push_back(Unit("U" + std::to_string(i), b[i], 0.01));
  fleet.push_back(Unit("planted", 3.25, 0.01));
  const auto flagged = FindOutOfSpread(fleet);
  ASSERT_EQ(flagged.size(), 1u);
  EXPECT_EQ(flagged[0].serial, "planted");
  EXPECT_EQ(flagged[0].parameter, "model.b");
  EXPECT_GT(flagged[0].z, flagged[0].threshold);
}

TEST(FleetSpread, TheMakesOwnSpreadAndAUnitsOwnSigmaAreNotFlagged) {
  std::vector<UnitRecord> fleet;
  // Units 2 % apart from one another, each known to 0.3 %: the make's spread, not an outlier.
  const double b[] = {2.95, 3.07, 3.01, 2.98, 3.04, 3.00, 3.03, 2.97};
  for (int i = 0; i < 8; ++i) fleet.push_back(Unit("U" + std::to_string(i), b[i], 0.01));
  EXPECT_TRUE(FindOutOfSpread(fleet).empty());
  // Far off, but its own calibration knows it to no better than that.
  fleet.back() = Unit("loose", 3.4, 0.2);
  EXPECT_TRUE(FindOutOfSpread(fleet).empty());
  // Too few units to know a spread: nothing is judged.
  fleet.resize(3);
  fleet.push_back(Unit("far", 5.0, 0.01));
  EXPECT_TRUE(FindOutOfSpread(fleet).empty());
}

}  // namespace
}  // namespace speckle::fleet
