#!/usr/bin/env bash
# Set-up (packages + build), then the main job on a built-in default: record a
# simulated session, show what it holds, and calibrate it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
session="demo/session-$(date +%Y%m%d-%H%M%S)"
build/record-session sim --out "$session" >/dev/null
build/session-info "$session"
echo
build/run-pipeline "$session"
echo
echo "demo: session in $(pwd)/$session, calibration under $(pwd)/$session/calibrations/"
