#!/usr/bin/env bash
# How body-body contact scales with the number of bodies: the first N rings of
# assets/scenes/torus_pile.toml (N = 1, 2, 4, 6, 8, 10), each timed by `softtled bench`
# with contact on and off (same mesh and FEM work). Usage:
#   bench/bodies_scaling.sh BUILD_DIR BACKEND [STEPS]
# Prints one row per N: tets, us/step with and without contact, the contact share.
set -euo pipefail
B=${1:?build dir}; BACKEND=${2:?cpu or cuda}; STEPS=${3:-2000}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TMP=$(mktemp -d); trap 'rm -rf "$TMP"' EXIT
printf "%-4s %-7s %-14s %-14s %s\n" N tets "contact us" "none us" "share"
for N in 1 2 4 6 8 10; do
  # The header, the first N [[body]] tables, then everything after the bodies.
  awk -v n="$N" '/^\[\[body\]\]/{b++} /^\[material\]/{b=99} b==0||b==99||(b>=1&&b<=n)' \
    "$ROOT/assets/scenes/torus_pile.toml" > "$TMP/pile$N.toml"
  med() { "$B/softtled" bench --scene "$TMP/pile$N.toml" --backend "$BACKEND" --steps "$STEPS" "$@" 2>&1 |
          awk '/us\/step: median/{print $3} /tets,/{t=$2} END{print t > "/dev/stderr"}'; }
  on=$(med 2>"$TMP/tets"); off=$(med --set contact.bodies=false 2>/dev/null)
  printf "%-4s %-7s %-14s %-14s %s\n" "$N" "$(cat "$TMP/tets")" "$on" "$off" \
    "$(awk -v a="$on" -v b="$off" 'BEGIN{printf "%.0f %%", 100*(a-b)/a}')"
done
