#!/usr/bin/env bash
# Sets up mimic2d on Debian 12: installs the Debian packages it needs (apt
# only), builds in Release, then runs `mimic2d demo` on the embedded default.
#   ./setup.sh            install + build + demo
#   ./setup.sh --no-demo  install + build only
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # libqhull-dev: mujoco's CMake target names /usr/include/libqhull_r
  libmujoco-dev libqhull-dev libtorch-dev libceres-dev libassimp-dev assimp-testmodels
  # libopenblas0-openmp: LibTorch's libblas.so.3; 4x faster PPO updates than
  # ATLAS here, and it follows LibTorch's thread setting (docs/benchmarks.md)
  libopenblas0-openmp
  # libcairo2-dev: overlays, PNG and text on rendered frames (brings glib)
  libosmesa6-dev libcairo2-dev ffmpeg gnuplot-nox
  # chromium: the test that opens the HTML report in a real (headless) browser
  chromium
)

missing=()
for package in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
    || missing+=("$package")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

echo "== building (Release) in build/"
mkdir -p build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > build/configure.log 2>&1 || { cat build/configure.log; exit 1; }
cmake --build build -j"$(nproc)"

if [ "${1:-}" != "--no-demo" ]; then
  echo "== mimic2d demo"
  ./build/mimic2d demo
fi
