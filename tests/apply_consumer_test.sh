#!/usr/bin/env bash
# Installs Speckle to a scratch prefix and builds tests/consumer against it
# with find_package(SpeckleApply), as another CMake project would, with only
# the public headers installed, then runs it on a calibration the pipeline
# wrote.
# usage: apply_consumer_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1") source=$(realpath "$2")
scratch=$(mktemp -d /tmp/speckle-consumer-XXXXXX)
trap 'rm -rf "$scratch"' EXIT
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
# Public headers only: what a user includes and what those include.
headers=$(cd "$scratch/prefix/include/speckle" && find . -name "*.h" | sort | tr '\n' ' ')
expected="./apply/depth_calibration.h ./apply/depth_corrector.h ./apply/pinhole_camera.h ./apply/point_measure.h ./apply/registered_depth.h ./model/covariates.h ./schemas/brown_conrady.h ./schemas/depth_units.h "
[[ "$headers" == "$expected" ]] || { echo "installed headers: $headers; expected: $expected" >&2; exit 1; }
# The package asks for Eigen only: Ceres, HDF5 and the rest stay inside the library.
if grep -E "find_dependency\((Ceres|HDF5|nlohmann_json|fmt)" "$scratch/prefix"/lib*/cmake/SpeckleApply/SpeckleApplyConfig.cmake; then
  echo "the installed package makes its users find the library's own dependencies" >&2
  exit 1
fi
cmake -S "$source/tests/consumer" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" -j2 >"$scratch/build.log" 2>&1 || { cat "$scratch/build.log"; exit 1; }
cp -r "$source/tests/golden/session" "$scratch/s"
"$build/run-pipeline" "$scratch/s" >/dev/null 2>&1
# Raw 800 is 1.247 m for the simulated sensor; every pixel with a ray has a
# point. The joint calibration's depth lens from this session's 10 poses
# (k3 -3.2 +- 1.3) stops inverting in the image's outermost corners, where
# no pose reached: 297057 of 307200 pixels have a ray (the separate steps'
# lens, over 300000).
out=$("$scratch/build/cloud_points" "$scratch/s/calibrations/v0001" 800)
echo "consumer: $out"
points=${out%% points*} depth=${out##*mean depth } depth=${depth%% m,*} registered=${out##*m, } registered=${registered%% *}
(( points > 291840 )) || { echo "expected more than 291840 points (95 %)" >&2; exit 1; }
# A flat scene at 1.25 m covers most of the colour image once registered to it.
(( registered > 200000 )) || { echo "expected more than 200000 registered colour pixels" >&2; exit 1; }
awk -v z="$depth" 'BEGIN { exit !(z > 1.2 && z < 1.3) }' || { echo "mean depth $depth m is not about 1.25 m" >&2; exit 1; }
