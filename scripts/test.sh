#!/usr/bin/env bash
# Set-up (packages + build), then the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --with-test-tools
cd build
ctest --output-on-failure -j2 --timeout 600
