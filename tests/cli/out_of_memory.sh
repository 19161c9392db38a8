#!/usr/bin/env bash
# out_of_memory.sh EXPECT_EXIT SOFTTLED SCENE
# Out of memory is a resource problem (exit 5, "out of memory"), never "internal error":
# a 200k-tet mesh under address-space limits from where the binary loads to 60 MB above
# (TetGen's child inherits them). Skipped
# (77) under AddressSanitizer, which needs terabytes of address space.
set -u
expect=$1 exe=$2 scene=$3
if ldd "$exe" 2>/dev/null | grep -q -e libasan -e libtsan; then echo "SKIP: sanitizer build"; exit 77; fi
# Several limits: TetGen 1.5 runs out at different allocations, some of which it does not
# check (it then dies of SIGSEGV, which the child reports as out of memory when its
# address space is at the limit); each must read as out of memory, not as a crash.
# The limits start where the binary itself loads (its size grows with every kernel and
# library linked in), found by starting it under rising limits.
base=20000
until ( ulimit -v $base; "$exe" --version >/dev/null 2>&1 ); do
  base=$(( base + 5000 ))
  [ $base -le 400000 ] || { echo "FAIL: softtled does not start under 400 MB of address space"; exit 1; }
done
for kb in $base $(( base + 15000 )) $(( base + 30000 )) $(( base + 60000 )); do
  ( ulimit -v $kb
    bash "$expect" 5 "out of memory" "$exe" mesh --scene "$scene" --set 'body.segments=[182,38]' \
      --set mesh.max_volume=0.01 --set mesh.cache=false ) || { echo "FAIL at ulimit -v $kb"; exit 1; }
done
# Threads: libgomp exits 1 ("Thread creation failed") when it cannot start a team, e.g. a
# thousand 8 MB stacks in 500 MB; the solver starts them first and reports the setting
# (exit 5). The control, two threads under the same limit, runs.
small=$(dirname "${BASH_SOURCE[0]}")/data/surface.toml
( ulimit -v $(( base + 500000 ))
  bash "$expect" 5 "1000 CPU threads (solver.threads, --threads): could not start 999 more threads" \
    "$exe" run --scene "$small" --set solver.threads=1000 &&
  bash "$expect" 0 "final centroid" "$exe" run --scene "$small" --set solver.threads=2 ) || { echo "FAIL: threads"; exit 1; }
# ... but threads that libgomp's idle team already holds are not started again: accuracy
# makes a solver per run, and 40 threads (320 MB of stacks) fit 500 MB once, not twice.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '\n[solver]\nthreads = 40\n' | cat "$(dirname "${BASH_SOURCE[0]}")/../../assets/scenes/torus_coarse.toml" - >"$tmp/t40.toml"
( ulimit -v $(( base + 500000 ))
  bash "$expect" 0 "wrote $tmp/acc/accuracy.csv" "$exe" accuracy --scene "$tmp/t40.toml" --levels 24x8 --ref 30x8 \
    --lambdas 1.0 --precisions float --elements T4 --t-end 0.002 --out "$tmp/acc" ) || { echo "FAIL: threads again"; exit 1; }
