#pragma once
// The diagnosis's conclusion from its numbers: which candidate to recommend
// (pose-level test), which covariate to name, and the verdict's words. Kept
// apart from the measurements (model_diagnosis.h) so the words can
// be checked against the numbers they come from.
#include <string>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

// Sets d.recommended (and the candidate's flag), d.named_covariate,
// d.formula_hint, d.test, d.test_poses, d.poses_needed, d.conclusion and
// d.verdict from the measured floor, covariates and candidates (ranked best
// first). The verdict's commands are parts of their own, for any session.
void ConcludeDiagnosis(const DiagnosisOptions& options, Diagnosis& d);

// Whether the recommended effect leaves the held-out error above
// complete_ratio times the floor: only then is a second effect looked for.
bool RecommendedLeavesExcess(const DiagnosisOptions& options, const Diagnosis& d);

// After the pair search (d.best_pair): what a second effect adds to the
// recommended one, and what remains, appended to the verdict.
void DescribePair(const DiagnosisOptions& options, Diagnosis& d);

// Last: why the joint judge given was not used (d.joint_declined), appended
// to the verdict, so a floor from the depth fit is not read as the joint one.
void SayJointDeclined(Diagnosis& d);

}  // namespace speckle
