#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs the main job: the viewer on the
# paper's torus drop when a display exists, otherwise a headless render (PNGs) and a
# headless simulation summary. Extra arguments go to the softtled command.
set -euo pipefail
source "$(dirname "$0")/setup.sh"
SCENE=${SOFTTLED_SCENE:-$ROOT/assets/scenes/torus_drop.toml}
BIN=$BUILD/softtled
has_cmd() { "$BIN" "$1" --help >/dev/null 2>&1; }
if [ -n "${DISPLAY:-}" ] && has_cmd view; then
  exec "$BIN" view --scene "$SCENE" "$@"
fi
if has_cmd render; then
  OUT=$ROOT/out/render
  "$BIN" render --scene "$SCENE" --at 0.02,0.05,0.1,0.2 --out "$OUT" "$@"
  echo "no display: rendered headless; PNGs in $OUT"
fi
mkdir -p "$ROOT/out"
"$BIN" run --scene "$SCENE" --csv "$ROOT/out/torus_drop.csv"
echo "trajectory: $ROOT/out/torus_drop.csv"
