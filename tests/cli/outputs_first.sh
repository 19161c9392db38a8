#!/usr/bin/env bash
# outputs_first.sh EXPECT_EXIT SOFTTLED DATA
# Output paths are checked before anything is meshed or written: with a bad --vtu (a
# file, not a directory) the run fails on it, not on the mesh it would have made (a
# mesh.max_volume far too small), and the CSV it would have truncated keeps its content.
set -u
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
echo precious >"$tmp/keep.csv"
echo file >"$tmp/plain"
bad_mesh=(--set mesh.max_volume=1e-12)
bash "$expect" 2 "--vtu $tmp/plain: exists and is not a directory" "$exe" run --scene "$data/surface.toml" "${bad_mesh[@]}" \
  --csv "$tmp/keep.csv" --vtu "$tmp/plain" || status=1
[ "$(cat "$tmp/keep.csv")" = precious ] || { echo "FAIL: keep.csv was truncated"; status=1; }
bash "$expect" 2 "--csv $tmp/nodir/x.csv: directory $tmp/nodir does not exist" "$exe" run --scene "$data/surface.toml" \
  "${bad_mesh[@]}" --csv "$tmp/nodir/x.csv" || status=1
bash "$expect" 2 "--csv $tmp: is a directory" "$exe" run --scene "$data/surface.toml" "${bad_mesh[@]}" --csv "$tmp" || status=1
bash "$expect" 2 "--vtu $tmp/plain/sub: $tmp/plain is not a directory" "$exe" run --scene "$data/surface.toml" "${bad_mesh[@]}" \
  --vtu "$tmp/plain/sub" || status=1
bash "$expect" 2 "--write $tmp/nodir/base.node: directory $tmp/nodir does not exist" "$exe" mesh --scene "$data/surface.toml" \
  "${bad_mesh[@]}" --write "$tmp/nodir/base" || status=1
bash "$expect" 2 "--vtu $tmp: is a directory" "$exe" mesh --scene "$data/surface.toml" "${bad_mesh[@]}" --vtu "$tmp" || status=1
bash "$expect" 2 "--json $tmp/nodir/b.json: directory $tmp/nodir does not exist" "$exe" bench --scene "$data/surface.toml" \
  "${bad_mesh[@]}" --json "$tmp/nodir/b.json" || status=1
[ ! -e "$tmp/nodir" ] || { echo "FAIL: $tmp/nodir was created"; status=1; }
exit $status
