#!/usr/bin/env bash
# Installs Speckle to a scratch prefix and builds tests/consumer against it
# with find_package(SpeckleApply), as another CMake project would, then runs
# it on a calibration the pipeline wrote.
# usage: apply_consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1") source=$(realpath "$2")
scratch=$(mktemp -d /tmp/speckle-consumer-XXXXXX)
trap 'rm -rf "$scratch"' EXIT
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
cmake -S "$source/tests/consumer" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" -j2 >"$scratch/build.log" 2>&1 || { cat "$scratch/build.log"; exit 1; }
cp -r "$source/tests/golden/session" "$scratch/s"
"$build/run-pipeline" "$scratch/s" >/dev/null 2>&1
# Raw 800 is 1.247 m for the simulated sensor; every pixel with a ray has a point.
out=$("$scratch/build/cloud_points" "$scratch/s/calibrations/v0001" 800)
echo "consumer: $out"
points=${out%% points*} depth=${out##*mean depth } depth=${depth% m}
(( points > 300000 )) || { echo "expected more than 300000 points" >&2; exit 1; }
awk -v z="$depth" 'BEGIN { exit !(z > 1.2 && z < 1.3) }' || { echo "mean depth $depth m is not about 1.25 m" >&2; exit 1; }
