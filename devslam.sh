#!/usr/bin/env bash
# DEV-SLAM driver: installs what is missing (Debian 12, as root), builds, runs.
#   ./devslam.sh demo        set up, build, run the main job on the shipped TUM frames
#   ./devslam.sh test        set up, build, run every test
#   ./devslam.sh test-asan   the same with AddressSanitizer + UndefinedBehaviorSanitizer
#   ./devslam.sh test-tsan   the same with ThreadSanitizer (OpenCV's loops serial, see cmake/)
#   ./devslam.sh bench       regenerate docs/RESULTS.md (all benchmark commands)
#   ./devslam.sh setup|build only those steps; packages: list the Debian packages
# Environment: BUILD_DIR (default build), JOBS (default 2).
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-2}

# Everything comes from Debian's archive; nothing is downloaded at build or run time.
PACKAGES=(build-essential cmake pkg-config
  libmrpt-dev mrpt-apps mrpt-common libopencv-dev opencv-doc libbullet-dev libeigen3-dev zlib1g-dev
  libboost-dev
  libgtest-dev libgmock-dev libbenchmark-dev)

setup() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then return 0; fi
  echo "devslam: installing ${missing[*]}" >&2
  local SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {  # build <dir> [cmake args...]
  local dir=$1; shift
  cmake -S "$ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  cmake --build "$dir" -j"$JOBS"
}

run_tests() {  # run_tests <dir> [command ctest runs under]
  (cd "$1" && "${@:2}" ctest --output-on-failure -j"$JOBS" --timeout 600)
}

case "${1:-}" in
  setup) setup ;;
  packages) echo "${PACKAGES[@]}" ;;
  build) setup; build "$BUILD_DIR" ;;
  demo)
    setup; build "$BUILD_DIR"
    "$BUILD_DIR/bin/devslam-run" "${@:2}" ;;
  test)
    setup; build "$BUILD_DIR"; run_tests "$BUILD_DIR" ;;
  test-asan)
    setup
    build "$BUILD_DIR-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEVSLAM_SANITIZE=ON -DDEVSLAM_BUILD_BENCHMARKS=OFF
    ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      run_tests "$BUILD_DIR-asan" ;;
  test-tsan)
    setup
    build "$BUILD_DIR-tsan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDEVSLAM_SANITIZE_THREAD=ON -DDEVSLAM_BUILD_BENCHMARKS=OFF
    # setarch -R: GCC 12's TSan runtime cannot map its shadow memory under the address-space
    # randomisation of recent kernels (every program dies at start); the children inherit it.
    TSAN_OPTIONS="halt_on_error=1 suppressions=$ROOT/tests/tsan.supp" \
      run_tests "$BUILD_DIR-tsan" setarch "$(uname -m)" -R ;;
  bench)  # every section of docs/RESULTS.md, regenerated (long: see docs/bench.md)
    setup; build "$BUILD_DIR"
    B="$BUILD_DIR/bin"
    "$B/devslam-filter-bench"                                   # section detect
    "$B/devslam-run" --bench 5                                  # section slam
    "$B/devslam-synth" walking_xyz --frames 300 -o out/synth/walking_xyz_300 --no-labels
    "$B/devslam-run" --bench 3 --modes-only --section slam-synthetic \
      --config config_ini/slam_synthetic.ini --input out/synth/walking_xyz_300   # section slam-synthetic
    "$B/devslam-bench"                                          # section bench (Tables 1-3)
    "$B/devslam-nav-bench"                                      # section nav
    "$BUILD_DIR/benchmarks/bench_nav"                           # Google Benchmark: A*, VFH+ step
    "$BUILD_DIR/benchmarks/bench_place"                         # Google Benchmark: place index
    "$BUILD_DIR/benchmarks/bench_pose" ;;                       # Google Benchmark: inlier bound
  *) sed -n '2,9p' "$0"; exit 2 ;;
esac
