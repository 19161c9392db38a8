#!/usr/bin/env bash
# vtu_bodies.sh SOFTTLED DATA
# `run --vtu DIR` of a two-body scene: one file per body per frame and a series.pvd that
# lists both parts of every frame with the same time step; the parts' point counts add up
# to the mesh's that the run reports. `mesh` prints a row per body and the total.
set -u
exe=$1 data=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; ls "$tmp/vtu" 2>/dev/null | head; cat "$tmp/err.txt" "$tmp/vtu/series.pvd" 2>/dev/null; exit 1; }
"$exe" run --scene "$data/bodies_valid.toml" --backend cpu --vtu "$tmp/vtu" >"$tmp/out.txt" 2>"$tmp/err.txt" || fail "exit code $?"
"$exe" mesh --scene "$data/bodies_valid.toml" --json >"$tmp/mesh.json" 2>>"$tmp/err.txt" || fail "mesh exit code $?"
python3 - "$tmp" <<'PY' || fail "files"
import json, os, re, sys
tmp = sys.argv[1]
d = os.path.join(tmp, "vtu")
files = sorted(os.listdir(d))
assert not any(re.fullmatch(r"frame_\d+\.vtu", f) for f in files), f"a whole-mesh frame with two bodies: {files}"
assert not any(f.endswith(".tmp") for f in files), files
pvd = open(os.path.join(d, "series.pvd")).read()
sets = re.findall(r'<DataSet timestep="([^"]+)" part="(\d)" file="([^"]+)"/>', pvd)
frames = {}
for t, part, f in sets:
    frames.setdefault(f.split("_b")[0], []).append((t, int(part), f))
assert len(frames) >= 2, pvd
mesh_nodes = int(re.search(r"mesh: (\d+) nodes", open(os.path.join(tmp, "err.txt")).read()).group(1))
report = json.load(open(os.path.join(tmp, "mesh.json")))
assert report["mesh_points"] == mesh_nodes == sum(b["mesh_points"] for b in report["bodies"]), (report, mesh_nodes)
for name, parts in frames.items():
    assert [p for _, p, _ in parts] == [0, 1], parts
    assert len({t for t, _, _ in parts}) == 1, f"parts of {name} at different times: {parts}"
    points = [int(re.search(r'NumberOfPoints="(\d+)"', open(os.path.join(d, f)).read()).group(1)) for _, _, f in parts]
    assert points == [b["mesh_points"] for b in report["bodies"]], (points, report["bodies"])
print("ok:", len(frames), "frames of 2 parts")
PY
