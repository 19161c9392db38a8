#!/usr/bin/env bash
# accuracy_assets.sh EXPECT_EXIT SOFTTLED
# `accuracy` without --scene finds scenes/torus_drop.toml under $SOFTTLED_ASSETS, as `view`
# does (here a scene with an unknown key, so the run is refused at once naming that file).
set -u
expect=$1 exe=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/assets/scenes" "$tmp/cwd"
printf '[material]\nyoung = 1\n' >"$tmp/assets/scenes/torus_drop.toml"
cd "$tmp/cwd" || exit 1
SOFTTLED_ASSETS=$tmp/assets bash "$expect" 2 "$tmp/assets/scenes/torus_drop.toml" "$exe" accuracy --out "$tmp/out" &&
  SOFTTLED_ASSETS=$tmp/assets bash "$expect" 2 "material.young: unknown key" "$exe" accuracy --out "$tmp/out" &&
  # Neither $SOFTTLED_ASSETS nor ./assets: the source tree's scene, in every build (it was
  # compiled in with the renderer only: "torus_drop.toml not found" without it). Refused
  # right after the scene loads, before any meshing.
  env -u SOFTTLED_ASSETS bash "$expect" 2 "is coarser than --levels" "$exe" accuracy --out "$tmp/out2" \
    --levels 200x40 --ref 91x19
