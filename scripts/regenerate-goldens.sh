#!/usr/bin/env bash
# Accepts the current results as the golden regression outputs: re-runs the
# golden test in writing mode, then shows what changed. Review the diff
# before committing it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
SPECKLE_REGENERATE_GOLDENS=1 build/tests/golden_test --gtest_filter=Golden.*
git --no-pager diff --stat -- tests/golden/
