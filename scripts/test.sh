#!/usr/bin/env bash
# Set-up (packages + build), then the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --with-test-tools
cd build
ctest --output-on-failure -j2 --timeout 600
# The sanitizer job: the fast tier under ASan + UBSan and a bounded run of
# every fuzz target (see scripts/sanitize.sh; its total time on a clean
# machine is not measured yet).
cd ..
bash scripts/sanitize.sh
