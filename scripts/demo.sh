#!/usr/bin/env bash
# Set-up (packages + build), then the main job on a built-in default: record a
# simulated session and show what it holds.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
session="demo/session-$(date +%Y%m%d-%H%M%S)"
build/record-session sim --out "$session" >/dev/null
build/session-info "$session"
echo
echo "demo: session written to $(pwd)/$session"
