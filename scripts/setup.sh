# Sourced by run.sh and test.sh: installs the Debian packages the build needs (only those
# missing), puts nvcc on PATH when the CUDA toolkit is present, configures and builds.
# Usage: source scripts/setup.sh [extra cmake args...]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${SOFTTLED_BUILD_DIR:-$ROOT/build}

source "$ROOT/scripts/packages.sh"
ensure_packages cmake g++ pkg-config libtet1.5-dev libtomlplusplus-dev libcli11-dev libeigen3-dev libhwy-dev \
  libgtest-dev libgmock-dev libbenchmark-dev libomp-dev \
  libgl-dev libegl-dev libglvnd-dev libegl-mesa0 libgl1-mesa-dri libglfw3-dev libglew-dev libimgui-dev libstb-dev \
  xvfb xauth xdotool imagemagick \
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib \
  ffmpeg  # render --video and the viewer's recording pipe frames to the ffmpeg program; ffprobe checks them in the tests

# The CUDA backend compiles wherever the toolkit is (it runs only where a GPU is).
if ! command -v nvcc >/dev/null && [ -x /usr/local/cuda/bin/nvcc ]; then
  export PATH=/usr/local/cuda/bin:$PATH
fi

cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
