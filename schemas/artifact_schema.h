#pragma once
// The calibration artifacts' schema versions, and the one check every reader
// of them makes (JSON and HDF5 alike). Layouts: schemas/calibration_format.md.
#include <H5Cpp.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace speckle {

inline constexpr int kCalibrationSchemaVersion = 3;  // 2: effects, parent_version, noise floor; 3: depth_delay_s (2 still read)
// Report 2: diagnosis, depth uncertainty, history; 3: consecutive-frame
// floor, quads, candidate sizes; 4: wall tilts (2 and 3 still read by refit).
inline constexpr int kReportSchemaVersion = 4;
// 2: gradient and velocity as vectors, board_point; 3: truth_sigma_m;
// 4: raw_rate (2 and 3 still read).
inline constexpr int kSamplesSchemaVersion = 4;
inline constexpr int kGridSchemaVersion = 1;
// apply-calibration's applied.json: what was written from which frames.
inline constexpr int kAppliedFramesSchemaVersion = 1;

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
int CheckSchema(const H5::H5File& file, const std::string& where, const std::string& name, int version, int oldest = -1);

}  // namespace speckle
