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
# Unwritable directory and file (root writes anywhere: only checked as another user).
if [ "$(id -u)" -ne 0 ]; then
  mkdir "$tmp/ro" && chmod 555 "$tmp/ro"
  bash "$expect" 2 "--csv $tmp/ro/x.csv: cannot write in directory $tmp/ro: Permission denied" "$exe" run \
    --scene "$data/surface.toml" "${bad_mesh[@]}" --csv "$tmp/ro/x.csv" || status=1
  bash "$expect" 2 "--vtu $tmp/ro/frames: cannot write in $tmp/ro: Permission denied" "$exe" run \
    --scene "$data/surface.toml" "${bad_mesh[@]}" --vtu "$tmp/ro/frames" || status=1
  chmod 444 "$tmp/keep.csv"
  bash "$expect" 2 "--csv $tmp/keep.csv: cannot write: Permission denied" "$exe" run \
    --scene "$data/surface.toml" "${bad_mesh[@]}" --csv "$tmp/keep.csv" || status=1
  chmod 755 "$tmp/ro"; chmod 644 "$tmp/keep.csv"
else
  echo "note: running as root; the unwritable-directory cases are not checked"
fi
[ ! -e "$tmp/nodir" ] || { echo "FAIL: $tmp/nodir was created"; status=1; }
exit $status
