#!/usr/bin/env bash
# The layers the linker enforces (top CMakeLists.txt): the tools that only
# read sessions and calibrations are not linked with the simulator, and the
# apply tools not with the pipeline. Checked on each tool's link line
# (CMake's link.txt): a static library on it is a dependency even where the
# linker happens to pull no object from it.
# Stage tests (SPECKLE_STAGE_TESTS in tests/CMakeLists.txt) are linked with
# speckle_stages and nothing above it, so a stage test cannot lean on the
# pipeline, the recorder or the simulator for its truth.
# The model lab's tests (after --lab) are linked with speckle_lab and nothing
# above it either.
# usage: layering_test.sh BUILD_DIR [STAGE_TEST...] [--lab LAB_TEST...]
set -euo pipefail
build=$1
shift
fail=0
link_line() { cat "$(find "$build" -path "*/$1.dir/link.txt" | head -1)"; }
refuse() {  # tool, library
  if [[ "$(link_line "$1")" == *"lib$2.a"* ]]; then
    echo "$1 is linked with $2" >&2
    fail=1
  fi
}
for tool in run-pipeline refit apply-calibration measure session-info; do refuse "$tool" speckle_simulator; done
for tool in apply-calibration measure session-info; do
  refuse "$tool" speckle_pipeline
  refuse "$tool" speckle_stages
done
above=(speckle_lab speckle_pipeline speckle_recorder speckle_sim_source speckle_simulator speckle_apply)
for test in "$@"; do
  if [[ $test == --lab ]]; then
    above=("${above[@]:1}")  # a lab test links the lab, and nothing above it
    continue
  fi
  [[ -n "$(find "$build" -path "*/$test.dir/link.txt" | head -1)" ]] || { echo "no link line for $test" >&2; fail=1; continue; }
  for layer in "${above[@]}"; do
    refuse "$test" "$layer"
  done
done
[[ "$(link_line record-session)" == *libspeckle_simulator.a* ]] || { echo "record-session lost its simulator" >&2; fail=1; }
exit $fail
