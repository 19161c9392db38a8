#!/usr/bin/env bash
# pipelined_run.sh SOFTTLED ASSETS
# `softtled run` checks output interval k while the device steps interval k + 1
# (Simulation::queue / collect); --sync-checks steps each interval only after the last is
# checked. Both must write the same CSV and VTU frames, byte for byte: with a fixed step and with the
# adaptive one, through the coarse paper drop's first impact (the step moves there).
# Backend auto: the GPU where there is one, else the CPU (same calls, nothing overlapping).
set -u
exe=$1 assets=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; cat "$tmp"/err_*.txt; exit 1; }
for dt in auto adaptive; do
  for how in pipelined sync; do
    flag=()
    [ "$how" = sync ] && flag=(--sync-checks)
    "$exe" run --scene "$assets/scenes/torus_drop.toml" --set body.segments=[45,9] --set time.dt=$dt \
      --set time.duration=0.07 --set time.output_every=0.001 --csv "$tmp/$dt.$how.csv" --vtu "$tmp/$dt.$how.vtu" \
      --every 5 "${flag[@]}" \
      >"$tmp/err_$dt.$how.txt" 2>&1 || fail "$dt $how: exit code $?"
  done
  rows=$(wc -l <"$tmp/$dt.sync.csv")
  [ "$rows" -eq 72 ] || fail "$dt: $rows lines, expected a header and 71 rows"
  cmp "$tmp/$dt.pipelined.csv" "$tmp/$dt.sync.csv" || fail "$dt: the pipelined CSV differs from --sync-checks"
  # The frames too: their velocities are du over the step du spans, which a pipelined
  # adaptive run had taken from the live step, already moved on (9-30 % off).
  for f in "$tmp/$dt.sync.vtu"/*; do
    cmp -s "$f" "$tmp/$dt.pipelined.vtu/$(basename "$f")" || fail "$dt: the pipelined $(basename "$f") differs from --sync-checks"
  done
  echo "ok: time.dt = $dt, $rows lines identical; $(grep '^simulated' "$tmp/err_$dt.pipelined.txt")"
done
