#pragma once
// A run's fingerprint: the SHA-256 of everything that decides the version it
// writes (this build's executable, the verb, the session's inputs or the
// parent version, the model spec and the options a user can set). A rerun
// whose fingerprint a version already carries would write the same
// numbers again, 36-92 MB of them, so it names that version instead.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace speckle {

// Hex digest of `what` (canonical JSON) with the running executable's own
// SHA-256 added: a rebuilt or upgraded tool never matches an older version.
std::string RunFingerprint(nlohmann::json what);

// The session's version whose calibration.json carries `fingerprint`, newest
// first; none when no version does (versions this tool cannot read, and
// versions from before fingerprints, never match).
std::optional<std::filesystem::path> VersionWithFingerprint(const std::filesystem::path& session_dir,
                                                            const std::string& fingerprint);

// What run-pipeline and refit do instead of a run when a version has their
// fingerprint: print that version, why nothing was written, its held-out
// error and how to write one anyway, then end as that version's run did
// (EndIfImplausible, pipeline/plausibility_gate.h).
void SayUnchanged(const std::filesystem::path& version);

}  // namespace speckle
