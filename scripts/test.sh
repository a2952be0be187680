#!/usr/bin/env bash
# Set-up (packages + build), then the whole test suite with ctest, then the
# sanitizer job: the fast tier under ASan + UBSan and a bounded run of every
# fuzz target (scripts/sanitize.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --with-test-tools
# The sanitizer tree is built beside the main suite at the lowest priority:
# it takes only the CPU the suite leaves idle (tests that wait on a daemon, a
# child or the disk; the last long test alone), and the suite keeps the rest.
mkdir -p build-sanitize
# Its own process group (set -m) so that a failed suite stops cmake, make and
# the compilers too; not its own session (setsid): with the kernel's
# autogroups a new session gets an equal share of the CPU whatever its nice.
set -m
nice -n 19 bash scripts/sanitize.sh build 2>build-sanitize/beside-the-suite.log &
builder=$!
set +m
trap 'kill -- -$builder 2>/dev/null || true' EXIT
suite_start=$(date +%s)
(cd build && ctest --output-on-failure -j2 --timeout 600)
echo "test: main suite in $(($(date +%s) - suite_start)) s" >&2
wait_start=$(date +%s)
if ! wait $builder; then
  cat build-sanitize/beside-the-suite.log >&2
  exit 1
fi
trap - EXIT
cat build-sanitize/beside-the-suite.log >&2
echo "test: waited $(($(date +%s) - wait_start)) s for the sanitizer build after the suite" >&2
bash scripts/sanitize.sh test
