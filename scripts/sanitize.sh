#!/usr/bin/env bash
# The sanitizer job: one clang build (build-sanitize/) with AddressSanitizer,
# UndefinedBehaviorSanitizer and libFuzzer's coverage, then the fast test tier
# (but the simulator's own rendering tests) under the sanitizers and a bounded
# run of every fuzz target (fuzz/). Any sanitizer finding or fuzzer crash
# fails it. scripts/test.sh runs it after
# the main suite; scripts/fuzz.sh runs the fuzz targets longer.
#   SPECKLE_FUZZ_SECONDS  seconds per fuzz target (default 30)
# With "build" it only builds (scripts/test.sh starts that beside the main
# suite); with "test" it only runs what an earlier build made.
set -euo pipefail
cd "$(dirname "$0")/.."
phase="${1:-all}"
[[ "$phase" =~ ^(all|build|test)$ ]] || { echo "usage: scripts/sanitize.sh [build|test]" >&2; exit 2; }
start=$(date +%s)
seconds="${SPECKLE_FUZZ_SECONDS:-30}"

build_tree() {
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  # -O1: the sanitizers' usual optimisation, a third of Release's compile time; line tables
  # only: enough for symbolized stack traces, and less to compile and link than -g.
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DSPECKLE_SANITIZE=ON -DSPECKLE_FUZZ=ON \
    -DSPECKLE_FUZZ_SECONDS="$seconds" "${launcher[@]}" >/dev/null
  # Only what the job runs: the fast tier with its tools, and the fuzz targets.
  if ! cmake --build build-sanitize -j"${SPECKLE_JOBS:-2}" --target speckle_fast_tier speckle_fuzz_targets \
    >build-sanitize/build.log 2>&1; then
    grep -E -A3 "error" build-sanitize/build.log | head -60 >&2
    echo "sanitize: build failed; full log in build-sanitize/build.log" >&2
    exit 1
  fi
  echo "sanitize: built in $(($(date +%s) - start)) s" >&2
}

run_tier() {
  local built
  built=$(date +%s)
  # Leaks are reported by LeakSanitizer at exit; the libraries' own one-time
  # allocations (HDF5, TBB, glog) are not ours.
  export ASAN_OPTIONS="detect_leaks=0:abort_on_error=0:halt_on_error=1"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  cd build-sanitize
  # The fast tier but the simulator's own rendering tests (tests/CMakeLists.txt
  # says why) and the tests that simulate whole sessions and calibrate them:
  # under ASan those took 85-300 s each (three hit their time limits, and the
  # tier 23 minutes of a 54-minute CI run on a loaded clean clone, 2026-11-24).
  # The same pipeline code runs sanitized in the golden, robustness, damaged-
  # recording, Calibrated and crash-safety tests, which the tier keeps.
  heavy="WallSegmentation.SimulatedWideAngleRooms|PipelineDepthCamera\.|AddRecordingEndToEnd\.|AppliedScene\."
  heavy+="|SimulatedMillimetres\.|FreenectIr.TheRecordedIrStep|Simulator.SameSeedSameFrames|Simulator.RawValuesFollow"
  # The killed recorder renders frames in real time: under ASan it did not write
  # its 3 MB within the test's 300 s (CI runs of 2026-11-26 and -27); the main suite runs it.
  heavy+="|CrashSafety\.KilledRecorder"
  # The joint hold-out fits five folds of a whole joint calibration twice: under
  # ASan one took 296 s and the other hit its 300 s limit (CI of 2026-12-02). The
  # joint problem's code runs sanitized in JointCalibration.*, and JointHoldOut's
  # refusal test stays.
  heavy+="|JointHoldOut\.AnEffectTheCamerasTookUp|JointHoldOut\.OnARigWithoutTheEffect"
  # The source-format check runs no code of ours; the main suite runs it.
  heavy+="|^clang_format$"
  # One more that renders whole simulated sessions: under ASan it rendered for
  # 154 s of a 57-minute clean-clone CI (2026-12-06). The simulator still runs
  # sanitized in the recording tests. (The plausibility gate's whole-session
  # test is in the slow tier since 2026-12-07; it runs sanitized in the
  # Calibrated tests.)
  heavy+="|Simulator\.FramesInAnyOrderEqualFramesRenderedAlone"
  # Whole pipelines run again, 82-94 s each under ASan (265 s of the tier's
  # 1564 s of test time, clean-clone CI of 2026-12-07): a rerun and a re-read of
  # the golden session, whose first run Golden.ArtifactsOfTheCommittedSessionMatch
  # keeps sanitized, and two refits of it for refit's sigma lines (a refit that
  # writes a version stays sanitized in RefitCosts.ParametersTheSamplesDoNot...).
  # The main suite runs all three.
  heavy+="|Golden\.FramesReadAgainGiveTheSameArtifacts|Golden\.ARerunWithNothingChangedWritesNoVersion|RefitCosts\.TheDepthSigma"
  ctest -L fast -LE simulator -E "$heavy" --output-on-failure -j2 --timeout 900
  local tested
  tested=$(date +%s)
  echo "sanitize: fast tier (but the simulator's rendering tests and whole simulated sessions) under ASan + UBSan in $((tested - built)) s" >&2
  ctest -L fuzz --output-on-failure -j2
  echo "sanitize: fuzz targets ${seconds} s each, in $(($(date +%s) - tested)) s; total $(($(date +%s) - start)) s" >&2
}

[[ "$phase" == test ]] || build_tree
[[ "$phase" == build ]] || run_tier
