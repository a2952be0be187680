#pragma once
// Adds recordings to an existing session, all or nothing. Users record the
// boards and the walls as separate libfreenect dumps; this puts the second
// dump into the first one's session without hand-editing session.json.
//
// Order of writes (each step leaves a valid session behind):
//  1. every new recording is written under a hidden name in the session
//     folder (".planar.h5.partial-NNN") and fsynced;
//  2. each is linked to its final name, which fails rather than overwrite;
//  3. session.json is replaced atomically (WriteSessionManifest).
// Any failure before step 3 completes removes what steps 1-2 made, so the
// session keeps exactly its old files and session.json bytes. Only a power
// cut between steps 2 and 3 can leave a recording session.json does not
// list; a later add names it and refuses to write over it.
#include <filesystem>

#include "recorder/session_recorder.h"

namespace speckle {

// Reads the manifest of the session to add to; InputError when the folder
// does not exist, holds no session.json, or holds one of an unknown version.
SessionManifest ReadSessionToAppendTo(const std::filesystem::path& session_dir);

// Refuses (InputError listing every conflict, see session_conflicts.h) a plan
// whose sensor, driver, depth units, image sizes or recording names do not fit
// the session. `plan.manifest` is the session's manifest as the user describes
// it now (ReadSessionToAppendTo's result with the source's and the flags'
// values laid over it); blanks it fills are kept. Holds an exclusive lock on
// the session folder so two adds cannot race.
SessionRecordSummary AppendToSession(SessionPlan plan, const std::filesystem::path& session_dir,
                                     const SessionRecorderOptions& options = {});

}  // namespace speckle
