#pragma once
// The calibration artifacts' schema versions, and the one check every reader
// of them makes (JSON and HDF5 alike). Layouts: schemas/calibration_format.md.
#include <H5Cpp.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "schemas/errors.h"
#include "schemas/h5_access.h"

namespace speckle {

// Calibration 2: effects, parent_version, noise floor; 3: depth_delay_s; 4:
// depth camera from the outlines; 5: the source ir_chessboard+depth_outlines
// (an IR camera refined with the outlines); 6: null where a joint board-plane
// fit determines nothing (outline_rms_px, the depth camera's reprojection
// rms) and translation_sigma_m from its jackknife, null when not determined.
// 10: a model parameter's `identified`, its sigmas null when false. 11:
// run_fingerprint (pipeline/run_fingerprint.h). 12: each camera's
// covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3 (null where only sigmas are known).
// 2 to 5 are still read.
inline constexpr int kCalibrationSchemaVersion = 12;
// Report 2: diagnosis, depth uncertainty, history; 3: consecutive-frame
// floor, quads, candidate sizes; 4: wall tilts; 5: the floor's cameras part,
// candidates against free cameras; 6: the diagnosis's coverage; 7: each
// planar snapshot's wall mask, wall share and tilt verdict, and the
// diagnosis's pose-level tests and each candidate's not_fitted reason (2 to 6 still read by refit: the diagnosis is
// rewritten); 8: step_seconds (wall-clock time of every fit, diagnosis
// candidate, camera perturbation and wall hold-out); 9: the diagnosis's
// conclusion and next_steps (its commands, structured); 10: depth_uncertainty
// rows past the boards, out to the sensor's usable range (`extrapolated`);
// 11: the covariate level "pose means, step"; 12: the floor's grid_raw;
// 13: the floor's neighbour_corners_raw; 14: each wall mask's reading_runs,
// and a planar frame rejected after segmentation keeps its wall_mask; 17: a
// fit parameter's `identified`, its sigmas null when false; 18:
// plots.time_s null when the frames carry no times; 19: assessment (good /
// limited by / not usable), cameras and warnings (pipeline/assessment.h);
// 20: the cameras' covariance (calibration.json 12); 21:
// depthboard_quads.board_size_in_depth (stages/board_size_in_depth.h).
inline constexpr int kReportSchemaVersion = 21;
// 2: gradient and velocity as vectors, board_point; 3: truth_sigma_m;
// 4: raw_rate; 5: perturbations_in_floor (2 to 4 still read: all in the floor).
inline constexpr int kSamplesSchemaVersion = 6;
inline constexpr int kGridSchemaVersion = 1;
// apply-calibration's applied.json: what was written from which frames.
// 2: a frame's time_s counts from the session's first frame (1: from its
// recording's).
inline constexpr int kAppliedFramesSchemaVersion = 3;  // 3: fold.max_error_at, fold.tables_used
// compare's comparison.json: two calibrations' depths against their sigmas.
inline constexpr int kComparisonSchemaVersion = 2;  // 2: share_differing and the rule

// Returns `found` when oldest (default: only `version`) <= found <= version,
// else throws SchemaVersionError naming `where` and the versions read.
int RequireSchemaVersion(const std::string& where, const std::string& schema, long long found, int version,
                         int oldest = -1);

// A JSON artifact whose "schema" is `schema`, of schema version
// oldest_version (default: only `version`) to `version`; throws
// SchemaVersionError for any other version, InputError for anything else wrong.
nlohmann::json ReadArtifactJson(const std::filesystem::path& path, const std::string& schema, int version,
                                int oldest_version = -1);

// The same for an HDF5 artifact's root attributes "schema" and
// "schema_version"; returns the file's version.
int CheckSchema(const H5::H5File& file, const std::string& where, const std::string& name, int version,
                int oldest = -1);

// Opens an HDF5 artifact, checks its schema (as CheckSchema) and returns
// read(file, version). Throws InputError "PATH: `missing`" when there is no
// file, and one naming the file and `what` when HDF5 cannot read it.
template <class Read>
auto ReadArtifactH5(const std::filesystem::path& path, const std::string& schema, int version, int oldest,
                    const std::string& missing, const std::string& what, Read read) {
  h5::SilenceLibraryErrors();
  const std::string where = path.string();
  if (!std::filesystem::exists(path)) throw InputError(where + ": " + missing);
  try {
    const H5::H5File file(where, H5F_ACC_RDONLY);
    return read(file, CheckSchema(file, where, schema, version, oldest));
  } catch (const H5::Exception& e) {
    throw InputError(where + ": unreadable " + what + ": " + e.getDetailMsg());
  }
}

}  // namespace speckle
