#!/usr/bin/env bash
# The layering README "Where the physics lives" promises, checked on the sources: render/
# includes nothing from sim/ or app/ (the app hands it buffers and plain geometry), and
# sim/ includes no OpenGL, EGL, GLFW, ImGui, render/ or app/ header.
# Usage: architecture_layers.sh SOURCE_ROOT
set -u
root=$1
nfail=0
report() {  # report WHAT MATCHES
  [ -z "$2" ] && return
  echo "FAIL: $1:"
  echo "$2"
  nfail=$((nfail + 1))
}
report "render/ includes sim/ or app/" \
  "$(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"(sim|app)/' "$root/render" || true)"
report "sim/ includes a GL, window, UI, render/ or app/ header" \
  "$(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](GL/|GLES|EGL/|GLFW/|imgui|render/|app/)' "$root/sim" || true)"
[ "$nfail" = 0 ] && echo "layers: render/ includes no sim/ or app/ header; sim/ no GL, window, UI, render/ or app/ header"
exit "$nfail"
