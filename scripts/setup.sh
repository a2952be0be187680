#!/usr/bin/env bash
# Installs the Debian packages Speckle needs (only the missing ones, quietly),
# the report's front-end assets from npm (report/package-lock.json), and
# builds it in ./build (Release, -j2). Safe to run again.
#   --with-test-tools  also the readers the tests check our files with (Chromium, PCL, Open3D, ...)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  cmake g++ make pkg-config
  libopencv-dev libeigen3-dev libceres-dev libhdf5-dev libaec-dev zlib1g-dev
  nlohmann-json3-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libspdlog-dev libfmt-dev libmuparser-dev libfreenect-dev
  libssl-dev hdf5-tools python3-h5py python3-numpy liblz4-dev hdf5-filter-plugin
  librosbag-storage-dev libsensor-msgs-dev
)
command -v npm >/dev/null || packages+=(npm)  # a machine's own Node.js may bring npm
# The tests' independent readers: a browser for the report; PCL, Open3D,
# Pillow, ROS's camera_info parser, OpenCV and PyYAML for apply-calibration's
# files; ROS's camera_calibration_parsers writer and mrcal for the camera
# files record-session reads; clang with its sanitizer and libFuzzer runtimes for scripts/sanitize.sh;
# clang-format for the house-style test.
[[ "${1:-}" == --with-test-tools ]] && packages+=(chromium pcl-tools python3-open3d python3-pil
  python3-camera-calibration-parsers camera-calibration-parsers-tools python3-mrcal python3-opencv python3-yaml
  python3-rosbag python3-sensor-msgs clang libclang-rt-dev clang-format
  slurmctld slurmd slurm-client munge)  # a one-node cluster for the fleet's Slurm row (scripts/slurm_one_node.sh)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=()
  [[ $EUID -ne 0 ]] && sudo_cmd=(sudo)
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

[[ -f report/node_modules/plotly.js-dist-min/plotly.min.js ]] ||
  npm ci --prefix report --no-audit --no-fund --loglevel=error >/dev/null

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
if ! cmake --build build -j2 >build/build.log 2>&1; then
  grep -E -A3 "error|Error" build/build.log | head -60 >&2
  echo "setup: build failed; full log in build/build.log" >&2
  exit 1
fi
echo "setup: built in $(pwd)/build" >&2
