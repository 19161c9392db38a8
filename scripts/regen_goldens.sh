#!/usr/bin/env bash
# Regenerates the screenshot-regression goldens in tests/golden/ (see
# tests/render/test_render_golden.cpp for the frames and the tolerance). Run it after an
# intended change to the renderer, the shaders or the physics, then LOOK at the new PNGs
# (torus recognisable, lit, resting on the floor at the end) before committing them.
# The goldens are made with Mesa llvmpipe through EGL, as CI renders them.
# Usage: scripts/regen_goldens.sh [build-dir]   (default: build; configured if needed)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
case "$build" in /*) ;; *) build="$root/$build" ;; esac
[ -f "$build/CMakeCache.txt" ] || cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j"$(nproc)" --target test_render_golden
export SOFTTLED_REGEN_GOLDENS=1 SOFTTLED_GOLDEN_DIR="$root/tests/golden" SOFTTLED_ASSETS="$root/assets"
export SOFTTLED_EGL_PLATFORM=${SOFTTLED_EGL_PLATFORM:-surfaceless}  # llvmpipe, as in CI
mkdir -p "$SOFTTLED_GOLDEN_DIR"
"$build/tests/render/test_render_golden"
echo "goldens in $SOFTTLED_GOLDEN_DIR:"
ls -l "$SOFTTLED_GOLDEN_DIR"/*.png
