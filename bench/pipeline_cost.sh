#!/usr/bin/env bash
# Instructions per explicit step (callgrind: repeatable whatever the machine's load) for
# the stages a scene enables: contact on/off, boundary vs all nodes, damping on/off,
# T4 vs T4ANP, float vs double. Per-step cost = (I(N2) - I(N1)) / (N2 - N1), so meshing
# and set-up cancel. Usage: bench/pipeline_cost.sh [build/softtled]
# The CPU step's SIMD stages run under valgrind on its AVX2 target (valgrind has no
# AVX-512). Where the CPU does not advertise RDTSCP (this repository's 2-core VM), libhwy's
# load-time constructor stops valgrind (SIGILL): count a build configured with
# -DSOFTTLED_SIMD_STATIC_AVX2=ON (AVX2 only, no libhwy), e.g. build-cg/softtled.
set -euo pipefail
BIN=${1:-build/softtled}
SCENE=assets/scenes/torus_drop.toml
count() {  # steps, then --set overrides
  local steps=$1; shift
  local f=$(mktemp)
  OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=$f "$BIN" run --scene $SCENE \
    --set time.dt=5e-6 time.duration=$(python3 -c "print($steps*5e-6)") time.output_every=1 "$@" >/dev/null 2>&1
  grep -m1 '^summary:' $f | awk '{print $2}'
  rm -f $f
}
printf "%-34s %14s\n" "variant (paper torus, 6936 tets)" "instr/step"
while IFS='|' read -r name sets; do
  a=$(count 20 $sets); b=$(count 120 $sets)
  printf "%-34s %14.0f\n" "$name" "$(python3 -c "print(($b-$a)/100)")"
done <<'LIST'
floor, boundary nodes (default)|
no planes (no contact stage)|floor.enabled=false
floor, contact on all nodes|contact.nodes=all
floor, no damping (alpha = 0)|damping.alpha=0
floor, coulomb friction|contact.mode=coulomb
floor, T4ANP|material.element=T4ANP
floor, float|solver.precision=float
LIST
