#!/usr/bin/env bash
# tet_roundtrip.sh SOFTTLED DATA ASSETS
# `mesh --vtu F` of the coarse torus, then F run as a tet_file body: the run reports the
# same node and tet counts and the same critical step that `mesh` printed for TetGen's mesh.
set -u
exe=$1 data=$2 assets=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; cat "$tmp/mesh.json" "$tmp/err.txt" 2>/dev/null; exit 1; }
"$exe" mesh --scene "$assets/scenes/torus_coarse.toml" --json --vtu "$tmp/torus.vtu" >"$tmp/mesh.json" 2>"$tmp/err.txt" ||
  fail "mesh exit code $?"
# The .vtu is in metres: body.scale = 1000 in a mm scene; material as torus_coarse's.
"$exe" run --scene "$data/tet_file.toml" --backend cpu --set body.file="$tmp/torus.vtu" --set body.scale=1000 \
  --set body.position=[0,0,0] --set material.nu=0.49 --set time.duration=0.001 >"$tmp/out.txt" 2>"$tmp/err.txt" ||
  fail "run exit code $?"
python3 - "$tmp" <<'PY' || fail "counts"
import json, re, sys
tmp = sys.argv[1]
report = json.load(open(tmp + "/mesh.json"))
err = open(tmp + "/err.txt").read()
m = re.search(r"mesh: (\d+) nodes, (\d+) tets, (\d+) surface nodes", err)
assert m, err
nodes, tets = int(m.group(1)), int(m.group(2))
assert (nodes, tets) == (report["mesh_points"], report["tetrahedra"]), (nodes, tets, report)
dt = float(re.search(r"dt_cr = ([0-9.e+-]+) us", err).group(1))
assert abs(dt - report["dt_cr_s"] * 1e6) <= 1e-3 * dt + 0.05, (dt, report["dt_cr_s"])
assert "inverted" not in err and "dropped" not in err, err
print("ok:", nodes, "nodes,", tets, "tets, dt_cr", dt, "us")
PY
