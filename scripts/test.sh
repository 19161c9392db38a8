#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs the whole test suite.
# Tests that need a GPU are skipped with a message on machines without one.
# The Python module's pytest files are ctest tests too (python.test_*, label python;
# python/CMakeLists.txt): `ctest -L python` runs them alone.
set -euo pipefail
source "$(dirname "$0")/setup.sh" "$@"
cd "$BUILD"
ctest --output-on-failure -j"$(nproc)" --timeout 600
