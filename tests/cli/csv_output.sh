#!/usr/bin/env bash
# csv_output.sh SOFTTLED DATA
# `--csv -` writes the CSV to standard output and the summary to standard error; the time
# column has enough digits that rows 1 ns apart are distinct and increasing.
set -u
exe=$1 data=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; echo "--- stdout"; head -20 "$tmp/out.csv"; echo "--- stderr"; cat "$tmp/err.txt"; exit 1; }
"$exe" run --scene "$data/surface.toml" --set time.dt=1e-9 --set time.duration=5e-9 --set time.output_every=1e-9 \
  --csv - >"$tmp/out.csv" 2>"$tmp/err.txt" || fail "exit code $?"
[ ! -e ./- ] || fail "a file named '-' was created"
head -1 "$tmp/out.csv" | grep -q '^t,cx,cy,cz,' || fail "stdout does not start with the CSV header"
grep -q '^simulated' "$tmp/out.csv" && fail "the summary went to stdout with the CSV"
grep -q '^simulated 5e-09 s in 5 steps' "$tmp/err.txt" || fail "no summary on stderr"
python3 - "$tmp/out.csv" <<'PY' || fail "time column"
import sys
lines = open(sys.argv[1]).read().splitlines()
t = [float(l.split(",")[0]) for l in lines[1:]]
assert len(t) == 6, t
assert all(b > a for a, b in zip(t, t[1:])), f"times not strictly increasing: {[l.split(',')[0] for l in lines[1:]]}"
assert abs(t[-1] - 5e-9) < 1e-12, t
print("ok:", [l.split(",")[0] for l in lines[1:]])
PY
