#!/usr/bin/env bash
# The layers the linker enforces (top CMakeLists.txt): the tools that only
# read sessions and calibrations are not linked with the simulator, and the
# apply tools not with the pipeline. Checked on each tool's link line
# (CMake's link.txt): a static library on it is a dependency even where the
# linker happens to pull no object from it.
# usage: layering_test.sh BUILD_DIR
set -euo pipefail
build=$1
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
[[ "$(link_line record-session)" == *libspeckle_simulator.a* ]] || { echo "record-session lost its simulator" >&2; fail=1; }
exit $fail
