#!/usr/bin/env bash
# accuracy_rows.sh SOFTTLED SCENE
# accuracy.csv and accuracy.md hold the same rows when a write fails part-way: under a file
# size limit that accuracy.md (the larger) passes first, the command exits 5 naming
# accuracy.md, and the CSV has as many rows as the table (it had one more: the CSV was
# committed before the Markdown failed).
set -u
exe=$1 scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
mkdir acc
( ulimit -f 1  # 1 KiB: accuracy.md passes it with its fourth row, accuracy.csv only later
  exec "$exe" accuracy --scene "$scene" --ref 12x5 --levels 10x4 --lambdas 0.25,0.5,1.0 --precisions float \
    --elements T4 --t-end 0.01 --out acc >out.txt 2>err.txt )
rc=$?
[ $rc -eq 5 ] && grep -q "^softtled: error: acc/accuracy.md: write failed: File too large" err.txt ||
  { echo "FAIL: exit $rc, wanted 5 naming accuracy.md"; cat err.txt; exit 1; }
csv=$(($(wc -l <acc/accuracy.csv) - 1))
md=$(grep -c '^| [0-9]' acc/accuracy.md)
[ "$csv" -eq "$md" ] && [ "$csv" -ge 1 ] || { echo "FAIL: accuracy.csv has $csv rows, accuracy.md $md"; exit 1; }
echo "ok: a failed accuracy.md leaves both files with the same $csv rows"
