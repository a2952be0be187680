#!/usr/bin/env bash
# Runs every fuzz target (fuzz/) for longer than CI does, one after the
# other, from the sanitizer build (scripts/sanitize.sh builds it). New
# interesting inputs collect in build-sanitize/fuzz/corpus/<target>; a crash
# leaves crash-* in build-sanitize/fuzz/ and fails the script.
#   scripts/fuzz.sh [SECONDS_PER_TARGET (default 600)] [TARGET ...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
shift || true
[[ -d build-sanitize/fuzz ]] || { echo "fuzz: run scripts/sanitize.sh first (it builds the targets)" >&2; exit 2; }
targets=("$@")
((${#targets[@]})) || targets=(fuzz_fakenect_dump fuzz_frames_folder fuzz_json_readers fuzz_recording_h5 fuzz_artifact_h5)
export ASAN_OPTIONS="detect_leaks=0:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-sanitize/fuzz
for t in "${targets[@]}"; do
  echo "fuzz: $t for $seconds s" >&2
  mkdir -p "corpus/$t"
  "./$t" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=3072 -print_final_stats=1 \
    "corpus/$t" "../../fuzz/corpus/$t" 2>"$t.log" || { tail -40 "$t.log" >&2; exit 1; }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$t.log" | sed "s/^/  $t /" >&2
done
