#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs the whole test suite.
# Tests that need a GPU are skipped with a message on machines without one.
set -euo pipefail
source "$(dirname "$0")/setup.sh" "$@"
cd "$BUILD"
ctest --output-on-failure -j"$(nproc)" --timeout 600
