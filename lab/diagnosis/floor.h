#pragma once
// The noise floor: the held-out error no depth model can go below with this
// data (the sensor's own scatter, the cameras' uncertainty, the grid's).
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

// The true depths' part in raw units: each sample's truth_sigma_m through
// the model's slope, as an RMS (-1: no sample has one).
double TruthPartRaw(const model::DepthModel& model, const std::vector<PairedSample>& samples);
// floor_raw and beyond_cameras_raw from the parts (sensor_raw, colour_pose_raw, cameras_raw, grid_raw).
void SumFloorParts(NoiseFloor& floor);

NoiseFloor EstimateFloor(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                         const std::vector<double>& grid_std_error_raw);

}  // namespace speckle
