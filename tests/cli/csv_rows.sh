#!/usr/bin/env bash
# csv_rows.sh EXPECT_EXIT SOFTTLED DATA
# The CSV holds only complete rows, each output time once:
# - a write error (a file size limit of 8 KiB, as on a full disk) exits 5 naming the file
#   and leaves the file cut back to its last complete row (no partial number at the end);
# - a watchdog stop (exit 4) does not repeat the last row: the rolled-back state is the
#   last row already written, so each t appears once and the last one is the time the
#   message says the state was rolled back to.
set -u
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
limited=(bash -c 'trap "" XFSZ; ulimit -f 8; exec "$@"' _)
bash "$expect" 5 "part.csv: write failed: File too large" "${limited[@]}" "$exe" run --scene "$data/surface.toml" \
  --set time.duration=1 --csv "$tmp/part.csv" || status=1
python3 - "$tmp/part.csv" <<'PY' || { echo "FAIL: partial row left"; tail -c 300 "$tmp/part.csv"; status=1; }
import sys
data = open(sys.argv[1]).read()
assert data.endswith("\n"), "the file ends mid-row: " + repr(data[-80:])
lines = data.splitlines()
n = len(lines[0].split(","))
assert len(lines) > 10, f"only {len(lines)} lines"
for l in lines[1:]:
    assert len(l.split(",")) == n, l
    [float(x) for x in l.split(",")]
PY
out=$("$exe" run --scene "$data/surface.toml" --set time.dt=5e-3 time.allow_unstable=true time.duration=1 --csv "$tmp/wd.csv" 2>&1)
rc=$?
[ $rc -eq 4 ] || { echo "FAIL: watchdog run exit $rc, wanted 4"; echo "$out"; status=1; }
back=$(sed -n 's/.*State rolled back to t = \([0-9.e+-]*\) s.*/\1/p' <<<"$out")
python3 - "$tmp/wd.csv" "$back" <<'PY' || { echo "FAIL: watchdog rows"; cat "$tmp/wd.csv" | cut -d, -f1; echo "$out"; status=1; }
import sys
lines = open(sys.argv[1]).read().splitlines()[1:]
ts = [l.split(",")[0] for l in lines]
assert len(ts) == len(set(ts)), f"a time appears twice: {ts}"
assert abs(float(ts[-1]) - float(sys.argv[2])) < 1e-9, f"last row t = {ts[-1]}, rolled back to {sys.argv[2]}"
PY
# The adaptive step stops within half a step of each output time: a duration less than
# half a step past the last one (this scene steps 24.9 us) adds no step, and no row.
"$exe" run --scene "$data/surface.toml" --set time.dt=adaptive time.duration=0.010005 --csv "$tmp/ad.csv" \
  >/dev/null 2>&1 || { echo "FAIL: adaptive run exit $?"; status=1; }
python3 - "$tmp/ad.csv" <<'PY' || { echo "FAIL: adaptive rows"; cut -d, -f1 "$tmp/ad.csv"; status=1; }
import sys
ts = [float(l.split(",")[0]) for l in open(sys.argv[1]).read().splitlines()[1:]]
assert all(b > a for a, b in zip(ts, ts[1:])), f"times not strictly increasing: {ts}"
assert abs(ts[-1] - 0.01) < 3e-5, f"last row at {ts[-1]}"
PY
# A fixed step that does not divide time.output_every: row k on the step nearest k
# output_every (a rounded step count per row drifted, and the last two rows came a step
# apart: 8 rows for 0.06 s every 0.01 s).
"$exe" run --scene "$data/surface.toml" --set time.dt=3.296e-5 time.duration=0.06 time.output_every=0.01 \
  --csv "$tmp/grid.csv" >/dev/null 2>&1 || { echo "FAIL: grid run exit $?"; status=1; }
python3 - "$tmp/grid.csv" <<'PY' || { echo "FAIL: rows off the output grid"; cut -d, -f1 "$tmp/grid.csv"; status=1; }
import sys
ts = [float(l.split(",")[0]) for l in open(sys.argv[1]).read().splitlines()[1:]]
assert len(ts) == 7, f"{len(ts)} rows, wanted 7: {ts}"
for k, t in enumerate(ts):
    assert abs(t - 0.01 * k) <= 0.5 * 3.296e-5 + 1e-9, f"row {k} at {t}"
PY
# The adaptive step with rows asked for every 1e-11 s: a row per step, at once (it spun
# through empty output intervals for ever).
out=$(timeout 60 "$exe" run --scene "$data/surface.toml" --set time.dt=adaptive time.duration=0.002 \
  time.output_every=1e-11 --csv "$tmp/fine.csv" 2>&1)
rc=$?
[ $rc -eq 0 ] || { echo "FAIL: adaptive run with output_every = 1e-11: exit $rc"; echo "$out"; status=1; }
steps=$(sed -n 's/.* in \([0-9]*\) steps of .*/\1/p' <<<"$out")
rows=$(( $(wc -l < "$tmp/fine.csv") - 2 ))
[ -n "$steps" ] && [ "$rows" -eq "$steps" ] || { echo "FAIL: $rows rows after t = 0 for $steps steps"; status=1; }
[ $status -eq 0 ] && echo "ok: no partial row after a write error, no repeated row after a watchdog stop or an adaptive end; rows on the output grid"
exit $status
