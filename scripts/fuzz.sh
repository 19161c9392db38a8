#!/usr/bin/env bash
# Fuzzes the surface loaders (OBJ, OFF, STL), the tet mesh readers (Gmsh .msh, VTK .vtu,
# TetGen .node/.ele, MEDIT .mesh, each with the import checks), the scene parser, and the path from a scene
# through placement to TetGen (fuzz_mesh) with libFuzzer, ASan and UBSan for a bounded time
# each, and fails on any finding (crash, TetGen assertion, sanitizer report, exception other
# than InputError, timeout, out-of-memory, leak).
#
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
#   SECONDS_PER_TARGET  default 60; 0 only replays the seed corpus and tests/fuzz/crashes
#   TARGET              fuzz_obj fuzz_off fuzz_stl fuzz_scene fuzz_mesh fuzz_msh fuzz_vtu fuzz_tetgen
#                       fuzz_medit (default: all)
# Environment: FUZZ_BUILD_DIR (default build-fuzz), CXX (default clang++).
#
# Seeds are read from tests/fuzz/corpus/<target>/ and never modified; new inputs go to
# $FUZZ_BUILD_DIR/corpus/<target>/, findings to $FUZZ_BUILD_DIR/artifacts/<target>/.
# Reproducers of bugs found earlier live in tests/fuzz/crashes/<target>/ and are replayed
# first. Replay one input: $FUZZ_BUILD_DIR/<target> FILE
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}
SECONDS_EACH=${1:-60}
shift || true
TARGETS=${*:-fuzz_obj fuzz_off fuzz_stl fuzz_scene fuzz_mesh fuzz_msh fuzz_vtu fuzz_tetgen fuzz_medit}
export CXX=${CXX:-clang++}

# Debian packages: clang (the compiler) and libclang-rt-14-dev (libFuzzer, ASan and UBSan
# runtimes of clang 14); installed only when missing.
source "$ROOT/scripts/packages.sh"
ensure_packages clang libclang-rt-14-dev cmake libtomlplusplus-dev libtet1.5-dev

cmake -S "$ROOT/tests/fuzz" -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER="$CXX" >/dev/null
cmake --build "$BUILD" -j"${FUZZ_BUILD_JOBS:-$(nproc)}" >/dev/null

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

declare -A MAX_LEN=([fuzz_obj]=4096 [fuzz_off]=4096 [fuzz_stl]=8192 [fuzz_scene]=8192 [fuzz_mesh]=8192)
declare -A DICT=([fuzz_obj]=obj [fuzz_off]=off [fuzz_stl]=stl [fuzz_scene]=scene [fuzz_mesh]=mesh)
MAX_LEN+=([fuzz_msh]=8192 [fuzz_vtu]=8192 [fuzz_tetgen]=4096 [fuzz_medit]=4096)
DICT+=([fuzz_msh]=msh [fuzz_vtu]=vtu [fuzz_tetgen]=tetgen [fuzz_medit]=medit)
# Seconds per input: fuzz_mesh runs TetGen (its tet budget is capped at 20000 in the
# harness, well under a second; the limit catches a TetGen run that does not end).
declare -A TIMEOUT=([fuzz_mesh]=30)
failed=()
summary=()
for t in $TARGETS; do
  [ -x "$BUILD/$t" ] || { echo "fuzz: unknown target '$t'" >&2; exit 2; }
  work="$BUILD/corpus/$t" art="$BUILD/artifacts/$t/" log="$BUILD/$t.log"
  mkdir -p "$work" "$art"
  dirs=("$work" "$ROOT/tests/fuzz/corpus/$t")
  if [ -d "$ROOT/tests/fuzz/crashes/$t" ] && [ -n "$(ls -A "$ROOT/tests/fuzz/crashes/$t")" ]; then
    dirs+=("$ROOT/tests/fuzz/crashes/$t")
  fi
  args=(-timeout="${TIMEOUT[$t]:-10}" -rss_limit_mb=2048 -max_len="${MAX_LEN[$t]}" -print_final_stats=1
        -dict="$ROOT/tests/fuzz/dict/${DICT[$t]}.dict" -artifact_prefix="$art")
  if [ "$SECONDS_EACH" = 0 ]; then args+=(-runs=0); else args+=(-max_total_time="$SECONDS_EACH"); fi
  echo "fuzz: $t for ${SECONDS_EACH} s (log: $log)"
  if "$BUILD/$t" "${args[@]}" "${dirs[@]}" >"$log" 2>&1; then
    last=$(grep -E '^#[0-9]+[[:space:]]+(DONE|INITED)' "$log" | tail -1)
    runs=$(grep -oE 'stat::number_of_executed_units:[[:space:]]*[0-9]+' "$log" | grep -oE '[0-9]+$' || true)
    rate=$(grep -oE 'stat::average_exec_per_sec:[[:space:]]*[0-9]+' "$log" | grep -oE '[0-9]+$' || true)
    cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' <<<"$last" || true)
    corp=$(grep -oE 'corp: [0-9]+/[0-9]+[a-zA-Z]*' <<<"$last" || true)
    summary+=("$t: ok, ${runs:-?} runs, ${rate:-?} exec/s, $cov, $corp")
  else
    failed+=("$t")
    summary+=("$t: FINDING")
    echo "---- $t: finding (last lines of $log) ----" >&2
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written|deadly|uncaught|timeout|out-of-memory' "$log" | head -20 >&2 || true
    tail -n 40 "$log" >&2
    echo "reproduce: $BUILD/$t <file from $art>; keep it in tests/fuzz/crashes/$t/" >&2
  fi
done
printf '%s\n' "${summary[@]}"
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: no findings"
