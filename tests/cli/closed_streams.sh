#!/usr/bin/env bash
# closed_streams.sh SOFTTLED SCENE TORUS_SCENE
# A standard stream started closed (>&-, 2>&-): the first file the run opens must not take
# its descriptor, or the summary or the log would be written into the CSV. The stream's
# writes fail instead, as on a full disk (exit 5), and the CSV holds its header and rows only.
set -u
exe=$1 scene=$2 torus=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
check() {  # WHAT: the CSV is a header and numeric rows of its width
  python3 - "$tmp/out.csv" <<'PY' || { echo "FAIL: $1: the CSV holds other text:"; head -5 "$tmp/out.csv"; status=1; }
import sys
lines = open(sys.argv[1]).read().splitlines()
n = len(lines[0].split(","))
assert len(lines) > 2, lines
for l in lines[1:]:
    assert len(l.split(",")) == n, l
    [float(x) for x in l.split(",")]
PY
}
"$exe" run --scene "$scene" --csv "$tmp/out.csv" >&- 2>"$tmp/err.txt"
rc=$?
[ $rc -eq 5 ] || { echo "FAIL: stdout closed: exit $rc, wanted 5"; status=1; }
grep -q "standard output: write failed: Bad file descriptor" "$tmp/err.txt" || { echo "FAIL: stdout closed: no message"; status=1; }
check "stdout closed"
"$exe" run --scene "$scene" --csv "$tmp/out.csv" 2>&- >/dev/null
rc=$?
[ $rc -eq 5 ] || { echo "FAIL: stderr closed: exit $rc, wanted 5"; status=1; }
check "stderr closed"
# accuracy prints each row to standard output as it writes it to accuracy.csv: with stdout
# closed, every row appeared twice in the CSV.
"$exe" accuracy --scene "$torus" --levels 24x8 --ref 30x8 --lambdas 1.0 --precisions float --elements T4 \
  --t-end 0.002 --out "$tmp/acc" >&- 2>/dev/null
rc=$?
[ $rc -eq 5 ] || { echo "FAIL: accuracy, stdout closed: exit $rc, wanted 5"; status=1; }
[ "$(sort "$tmp/acc/accuracy.csv" | uniq -d | wc -l)" -eq 0 ] && [ "$(wc -l <"$tmp/acc/accuracy.csv")" -eq 4 ] ||
  { echo "FAIL: accuracy, stdout closed: accuracy.csv is not its header and 3 rows:"; cat "$tmp/acc/accuracy.csv"; status=1; }
[ $status -eq 0 ] && echo "ok: closed standard streams fail their writes (exit 5), the CSV stays clean"
exit $status
