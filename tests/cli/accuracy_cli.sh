#!/usr/bin/env bash
# accuracy_cli.sh EXPECT_EXIT SOFTTLED SCENE
# `softtled accuracy`: bad arguments fail before the reference run and create nothing;
# without --out it writes to a new ./accuracy-DATE-TIME directory (never the committed
# bench/accuracy), prints a progress line with an ETA per run, and writes accuracy.csv
# and accuracy.md.
set -u
expect=$1 exe=$2 scene=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
status=0
bash "$expect" 2 "--lambdas '0.5,abc': 'abc' is not a number" "$exe" accuracy --scene "$scene" --lambdas 0.5,abc || status=1
bash "$expect" 2 "--adaptive-lambdas '2': '2' is not a number" "$exe" accuracy --scene "$scene" --adaptive-lambdas 2 || status=1
bash "$expect" 2 "--levels '91y19': expected NUxNV" "$exe" accuracy --scene "$scene" --levels 91y19 || status=1
bash "$expect" 2 "--precisions: 'half'" "$exe" accuracy --scene "$scene" --precisions half || status=1
bash "$expect" 2 "--t-end: must be finite" "$exe" accuracy --scene "$scene" --t-end nan || status=1
bash "$expect" 2 "--ref-lambda: value 2 not in" "$exe" accuracy --scene "$scene" --ref-lambda 2 || status=1
bash "$expect" 2 "body.segments" "$exe" accuracy --scene "$scene" --ref 2x2 || status=1
[ -z "$(ls)" ] || { echo "FAIL: a refused run created $(ls)"; status=1; }
# --backend cuda where there is none (no CUDA in the build, or no device) is refused
# before the reference is meshed and before --out is created; with a device it runs.
"$exe" accuracy --scene "$scene" --backend cuda --out acc_cuda --ref 12x5 --levels 10x4 --lambdas 0.5 --precisions float \
  --elements T4 --t-end 0.01 >out.txt 2>err.txt
rc=$?
if [ $rc -eq 2 ]; then
  grep -q "^softtled: error: backend 'cuda': " err.txt && ! grep -q '^\[1/' err.txt && [ ! -e acc_cuda ] ||
    { echo "FAIL: --backend cuda without CUDA: not refused first"; cat err.txt; ls acc_cuda 2>/dev/null; status=1; }
elif [ $rc -ne 0 ]; then
  echo "FAIL: --backend cuda exited with $rc"; cat err.txt; status=1
fi
rm -rf acc_cuda out.txt err.txt
"$exe" accuracy --scene "$scene" --ref 12x5 --levels 10x4 --lambdas 0.5 --adaptive-lambdas 0.5 --precisions float \
  --elements T4 --t-end 0.01 >out.txt 2>err.txt || { echo "FAIL: accuracy exited with $?"; cat err.txt; exit 1; }
dir=$(ls -d accuracy-* 2>/dev/null | head -1)
[ -n "$dir" ] || { echo "FAIL: no accuracy-* directory"; ls; exit 1; }
# header, the two reference rows, the fixed-step row and the adaptive one (marked so, with
# errors measured like the others)
[ "$(wc -l <"$dir/accuracy.csv")" -eq 5 ] && sed -n 4p "$dir/accuracy.csv" | grep -q ',auto$' &&
  sed -n 5p "$dir/accuracy.csv" | grep -Eq '^10x4,[0-9]+,float,T4,0.5,[0-9.e+-]+,[0-9]+,([0-9.e+-]+,){8}adaptive$' ||
  { echo "FAIL: accuracy.csv"; cat "$dir/accuracy.csv"; status=1; }
grep -q '^| level | ntet |' "$dir/accuracy.md" && [ "$(grep -c '^| 1' "$dir/accuracy.md")" -eq 4 ] ||
  { echo "FAIL: accuracy.md"; cat "$dir/accuracy.md"; status=1; }
grep -q '^\[1/4\] 12x5 double T4ANP' err.txt && grep -q '^\[4/4\] 10x4 float T4 lambda 0.5.*left)' err.txt ||
  { echo "FAIL: progress lines"; cat err.txt; status=1; }
# accuracy.csv a FIFO: its reader takes every row (the CSV, rewritten whole per row for a
# file, is written once, in place, to a FIFO: reopened, its reader saw the end after one row)
mkdir fifo_out && mkfifo fifo_out/accuracy.csv
cat fifo_out/accuracy.csv >fifo_rows.csv &
reader=$!
"$exe" accuracy --scene "$scene" --ref 12x5 --levels 10x4 --lambdas 0.5 --precisions float --elements T4 \
  --t-end 0.01 --out fifo_out >/dev/null 2>err.txt || { echo "FAIL: accuracy into a FIFO exited with $?"; cat err.txt; status=1; }
wait $reader
[ "$(wc -l <fifo_rows.csv)" -eq 4 ] || { echo "FAIL: the FIFO's reader got:"; cat fifo_rows.csv; status=1; }
[ $status -eq 0 ] && echo "ok: validated first, $dir/accuracy.csv and accuracy.md, progress with ETA, a FIFO's reader"
exit $status
