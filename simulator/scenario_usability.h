#pragma once
// Whether a parsed scenario can give a session anything to calibrate from:
// each key is in range on its own, but together they can still record
// nothing, put the board beyond the depth model's readings, or shrink its
// squares below what a chessboard detector finds. Such a scenario is refused
// before a frame is rendered, naming the keys, instead of recording a session
// every later step refuses.
#include <string>

#include "simulator/scenario.h"

namespace speckle::sim {

// Throws InputError naming `origin` and the keys at fault.
void CheckUsable(const Scenario& scenario, const std::string& origin);

// Smallest square, in colour pixels at the farthest board pose, that the
// chessboard detector is asked to find: a bound on the simulator's input, not
// the detector's measured limit, set below the shipped scenarios' smallest
// (6.0 px, drawn at seeds 1-30: tests/scenario_test.cc prints it) so that it
// refuses only boards far beyond anything the tool was built on.
inline constexpr double kMinSquarePx = 4;

}  // namespace speckle::sim
