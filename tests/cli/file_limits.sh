#!/usr/bin/env bash
# file_limits.sh EXPECT SOFTTLED DATA
# Writes that fail part-way leave no broken output:
# - past a file-size limit (ulimit -f) a write fails like one on a full disk (exit 5
#   naming the file, the CSV cut back to its last complete row, no PATH.tmp left), where
#   SIGXFSZ had killed the program mid-row;
# - a first VTU frame that fails leaves an earlier CSV untouched;
# - a TetGen .node/.ele pair is replaced both or neither: the second file failing keeps
#   the old pair (a new .node had been left beside the old .ele);
# - a temporary's name (PATH.tmp) taken by a directory is refused before the work.
set -u
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
status=0
(ulimit -f 8; bash "$expect" 5 "fc.csv" "$exe" run --scene "$data/surface.toml" --backend cpu --csv fc.csv --set time.duration=0.2) || status=1
[ -s fc.csv ] && [ -z "$(tail -c1 fc.csv)" ] || { echo "FAIL: fc.csv is empty or ends mid-row"; status=1; }
# The first VTU frame past the limit: the CSV of an earlier run is left as it was (it was
# opened, and emptied, before the frame was written).
cp fc.csv keep.csv
(ulimit -f 1; bash "$expect" 5 "frame_00000.vtu: write failed" "$exe" run --scene "$data/surface.toml" --csv keep.csv \
  --vtu kv) || status=1
cmp -s fc.csv keep.csv || { echo "FAIL: a run whose first frame failed changed the earlier CSV"; status=1; }
echo old > m.vtu
(ulimit -f 4; bash "$expect" 5 "m.vtu" "$exe" mesh --scene "$data/surface.toml" --vtu m.vtu --set "body.shape=sphere" --set body.radius=3) || status=1
[ "$(cat m.vtu)" = old ] && [ ! -e m.vtu.tmp ] || { echo "FAIL: m.vtu replaced or m.vtu.tmp left"; status=1; }
bash "$expect" 0 "Mesh tetrahedra" "$exe" mesh --surface "$data/tetrahedron.obj" --write m || status=1
sum=$(cat m.node m.ele | md5sum)
# The second file past the size limit (this mesh: .node 212 KiB, .ele 233 KiB).
(ulimit -f 220; bash "$expect" 5 "m.ele" "$exe" mesh --scene "$data/surface.toml" --write m --set "body.shape=sphere" \
  --set body.radius=3 --set mesh.max_volume=0.05) || status=1
[ "$(cat m.node m.ele | md5sum)" = "$sum" ] && [ ! -e m.node.tmp ] && [ ! -e m.ele.tmp ] ||
  { echo "FAIL: the .node/.ele pair changed or a .tmp left"; status=1; }
# A temporary's name taken by a directory: refused before meshing (exit 2), the directory
# left alone (it had been removed), the pair unchanged.
mkdir m.ele.tmp
bash "$expect" 2 "--write m.ele: it is written to m.ele.tmp first, which is a directory" "$exe" mesh \
  --scene "$data/surface.toml" --write m --set "body.shape=sphere" --set body.radius=3 || status=1
[ -d m.ele.tmp ] && [ "$(cat m.node m.ele | md5sum)" = "$sum" ] || { echo "FAIL: m.ele.tmp removed or the pair changed"; status=1; }
[ $status -eq 0 ] && echo "ok: file-size limit and a failing pair leave no broken output"
exit $status
