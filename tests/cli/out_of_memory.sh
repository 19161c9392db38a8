#!/usr/bin/env bash
# out_of_memory.sh EXPECT_EXIT SOFTTLED SCENE
# Out of memory is a resource problem (exit 5, "out of memory"), never "internal error":
# a 200k-tet mesh under a 30 MB address-space limit (TetGen's child inherits it). Skipped
# (77) under AddressSanitizer, which needs terabytes of address space.
set -u
expect=$1 exe=$2 scene=$3
if ldd "$exe" 2>/dev/null | grep -q -e libasan -e libtsan; then echo "SKIP: sanitizer build"; exit 77; fi
ulimit -v 30000
bash "$expect" 5 "out of memory" "$exe" mesh --scene "$scene" --set 'body.segments=[182,38]' --set mesh.max_volume=0.01 \
  --set mesh.cache=false
