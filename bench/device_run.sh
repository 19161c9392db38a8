#!/usr/bin/env bash
# One call on the GPU machine: build with CUDA, the CUDA tests, the benches
# (Table II form, sweep), an Nsight Compute look at the two step kernels, and
# compute-sanitizer memcheck on a short torus drop. Run from the project root there:
#   source .gl/setup.sh && bench/device_run.sh [SOURCE_DIR] [STAGES]
# SOURCE_DIR defaults to "."; STAGES is a list of words from
#   build test bench cpu sanitize ncu ncu1m all-tests   (default: all but ncu1m)
# (bench/ holds Google Benchmark CPU benches, off here: libbenchmark is not carried.)
# Logs and JSON go to $OUT (the device tool's folder) or /tmp/out; a summary prints last.
set -uo pipefail
SRC=$(cd "${1:-.}" && pwd)
STAGES=${2:-"build test bench cpu sanitize ncu all-tests"}
NCU_SECTIONS="--section SpeedOfLight --section MemoryWorkloadAnalysis --section LaunchStats --section Occupancy --section WarpStateStats"
NCU_GREP="^  [a-z_]+.*\(|Duration|Memory Throughput|DRAM Throughput|Compute \(SM\)|Achieved Occupancy|Registers Per|Block Size|Grid Size|L2 Hit|L1/TEX Hit|Mem Busy|Max Bandwidth|Warp Cycles Per Issued"
B=${SOFTTLED_DEVICE_BUILD:-/tmp/build}
OUT=${OUT:-/tmp/out}
mkdir -p "$OUT"
LOG=$OUT/log.txt
SCENE=$SRC/assets/scenes/torus_drop.toml
has() { [[ " $STAGES " == *" $1 "* ]]; }
say() { echo "== $*" | tee -a "$LOG"; }

nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,temperature.gpu,power.draw --format=csv |
  tee -a "$LOG"
nproc | sed 's/^/cpu cores: /' | tee -a "$LOG"

if has build; then
  say "build ($SRC)"
  t0=$(date +%s)
  # Keep going past a broken target elsewhere in the tree; stop only if ours are missing.
  { cmake -S "$SRC" -B "$B" $SOFTTLED_DEVICE_CMAKE_ARGS -DSOFTTLED_CUDA=ON -DSOFTTLED_BUILD_BENCH=OFF &&
    cmake --build "$B" -j16 -- -k; } > "$OUT/build.log" 2>&1 || grep -E "error|Error" "$OUT/build.log" | head -20
  if [ ! -x "$B/softtled" ] || [ ! -x "$B/tests/solver/cuda/test_cuda_solver" ]; then
    tail -40 "$OUT/build.log"
    exit 1
  fi
  say "built in $(( $(date +%s) - t0 )) s"
  rm -f "$OUT/build.log"
fi

if has test; then
  say "CUDA tests"
  (cd "$B" && ctest -R "CudaSolver|CudaAnp|BackendSelection|MeshReorder" --output-on-failure -V) > "$OUT/ctest_cuda.log" 2>&1
  echo "ctest (cuda) rc=$?" | tee -a "$LOG"
  grep -E "max \|x\| diff|Test +#.*(Passed|Failed|Skipped)|Failure|Expected|Which is" "$OUT/ctest_cuda.log" | tee -a "$LOG"
fi

if has bench; then
  say "bench cuda (torus, 8000 steps, sweep)"
  "$B/softtled" bench --scene "$SCENE" --backend cuda --steps 8000 --sweep --json "$OUT/bench_cuda.json" 2>&1 | tee -a "$LOG"
fi

if has cpu; then
  say "bench cpu (automatic threads)"
  "$B/softtled" bench --scene "$SCENE" --backend cpu --steps 8000 --json "$OUT/bench_cpu.json" 2>&1 | tee -a "$LOG"
  say "bench cpu (16 threads)"
  "$B/softtled" bench --scene "$SCENE" --backend cpu --steps 8000 --threads 16 --json "$OUT/bench_cpu16.json" 2>&1 | tee -a "$LOG"
fi

if has sanitize; then
  for mode in multi fused halo graph-pdl graph; do
    say "compute-sanitizer memcheck: torus drop, 5 ms, mode $mode"
    SOFTTLED_CUDA_MODE=$mode compute-sanitizer --tool memcheck --leak-check full --error-exitcode 9 \
      "$B/softtled" run --scene "$SCENE" --backend cuda --set time.duration=0.005 solver.precision=float > "$OUT/memcheck_$mode.txt" 2>&1
    echo "memcheck ($mode) rc=$?" | tee -a "$LOG"
    grep -E "ERROR SUMMARY|LEAK SUMMARY|simulated" "$OUT/memcheck_$mode.txt" | tee -a "$LOG"
    rm -f "$OUT/memcheck_$mode.txt"
  done
  for mode in multi fused halo; do
    say "compute-sanitizer racecheck: $mode step (shared memory), torus drop, 2 ms"
    SOFTTLED_CUDA_MODE=$mode compute-sanitizer --tool racecheck --error-exitcode 9 \
      "$B/softtled" run --scene "$SCENE" --backend cuda --set time.duration=0.002 solver.precision=float > "$OUT/racecheck.txt" 2>&1
    echo "racecheck ($mode) rc=$?" | tee -a "$LOG"
    grep -E "RACECHECK SUMMARY|ERROR SUMMARY|hazard" "$OUT/racecheck.txt" | head -5 | tee -a "$LOG"
    rm -f "$OUT/racecheck.txt"
  done
  say "compute-sanitizer memcheck: render, energy, external forces"
  compute-sanitizer --tool memcheck --error-exitcode 9 "$B/tests/solver/cuda/test_cuda_solver" \
    --gtest_filter='*Render*:*External*' > "$OUT/memcheck_tests.txt" 2>&1
  echo "memcheck (tests) rc=$?" | tee -a "$LOG"
  grep -E "ERROR SUMMARY|PASSED|FAILED" "$OUT/memcheck_tests.txt" | tee -a "$LOG"
  rm -f "$OUT/memcheck_tests.txt"
fi

if has ncu; then
  say "ncu: element and node kernels on the torus"
  ncu $NCU_SECTIONS -k regex:'element_forces|node_|fused_step|halo_step' -c 4 \
    "$B/softtled" run --scene "$SCENE" --backend cuda --set time.duration=0.0002 solver.precision=float > "$OUT/ncu.txt" 2>&1
  echo "ncu rc=$?" | tee -a "$LOG"
  grep -E "$NCU_GREP" "$OUT/ncu.txt" | head -60 | tee -a "$LOG"
fi

if has ncu1m; then
  say "ncu: element and node kernels on the 1M-tet torus (mesh from the cache the sweep filled)"
  ncu $NCU_SECTIONS -k regex:'element_forces|node_|fused_step|halo_step' -c 2 \
    "$B/softtled" run --scene "$SCENE" --backend cuda --set 'body.segments=[360,72]' mesh.max_volume=0.0018 \
    time.duration=2e-6 solver.precision=float > "$OUT/ncu1m.txt" 2>&1
  echo "ncu rc=$?" | tee -a "$LOG"
  grep -E "$NCU_GREP" "$OUT/ncu1m.txt" | head -40 | tee -a "$LOG"
fi

if has all-tests; then
  say "whole test suite"
  (cd "$B" && ctest -j16 --timeout 300) > "$OUT/ctest_all.log" 2>&1
  echo "ctest (all) rc=$?" | tee -a "$LOG"
  tail -15 "$OUT/ctest_all.log" | tee -a "$LOG"
fi
say done
