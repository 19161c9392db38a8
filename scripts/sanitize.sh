#!/usr/bin/env bash
# Builds the CPU code and the test suite with AddressSanitizer and UndefinedBehaviorSanitizer
# in a separate build directory (build-asan) and runs ctest; fails on any test failure and
# on any sanitizer report. The flags are given on the command line, not in CMakeLists.txt.
# Usage: scripts/sanitize.sh [extra cmake args...]
# Environment: SANITIZE_BUILD_DIR (default build-asan), CTEST_ARGS (e.g. "-R Scene").
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ASAN_BUILD=${SANITIZE_BUILD_DIR:-$ROOT/build-asan}

# -O1 keeps the solver tests fast enough; Debug keeps assert() on; no recovery from UB.
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1"
# setup.sh installs missing Debian packages (gcc's libasan8/libubsan1 come with g++),
# then configures and builds $SOFTTLED_BUILD_DIR with these arguments after its own.
SOFTTLED_BUILD_DIR=$ASAN_BUILD source "$ROOT/scripts/setup.sh" \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS="$SAN" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DSOFTTLED_CUDA=OFF -DSOFTTLED_RENDER=OFF -DSOFTTLED_BUILD_BENCH=OFF "$@"

# Every report aborts the process (non-zero exit); leaks are reported at exit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
cd "$ASAN_BUILD"
status=0
# shellcheck disable=SC2086
ctest --output-on-failure -j"$(nproc)" --timeout 1800 ${CTEST_ARGS:-} || status=$?
# A report in a test that expects a failing exit (the CLI tests) must not pass unnoticed.
if grep -lE 'ERROR: (AddressSanitizer|LeakSanitizer)|runtime error:' Testing/Temporary/LastTest*.log >/dev/null 2>&1; then
  echo "sanitize: sanitizer reports in the test log:" >&2
  { grep -nE -A30 'ERROR: (AddressSanitizer|LeakSanitizer)|runtime error:' Testing/Temporary/LastTest*.log || true; } | head -n 120 >&2 || true
  status=1
fi
if [ "$status" -ne 0 ]; then
  echo "sanitize: FAILED (log: $ASAN_BUILD/Testing/Temporary/LastTest.log)" >&2
  exit "$status"
fi
echo "sanitize: all tests pass under ASan + UBSan"
