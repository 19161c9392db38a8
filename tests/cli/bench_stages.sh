#!/usr/bin/env bash
# bench_stages.sh FRAGMENT PROGRAM [ARGS...]
# Runs `PROGRAM ARGS` (a CPU bench); passes when it exits 0, its output contains FRAGMENT
# (fixed string; the mode line names the CPU path) and the per-stage row's times are
# finite numbers: f, u and render write above 0, contact at least 0 (a difference of two
# timings, clamped). Fails on a signal (a crash), a hang or a missing row.
set -u
fragment=$1
shift
out=$(timeout "${SOFTTLED_CLI_TIMEOUT:-240}" "$@" 2>&1)
rc=$?
CMD=$(printf '%q ' "$@")
fail() {
  echo "FAIL: $*"
  echo "command: $CMD"
  echo "exit code: $rc"
  echo "---- output ----"
  printf '%s\n' "$out" | tail -n 40
  exit 1
}
if [ "$rc" -eq 124 ]; then fail "hung (timeout)"; fi
if [ "$rc" -ge 128 ]; then fail "killed by signal $((rc - 128)) (crash)"; fi
if [ "$rc" -ne 0 ]; then fail "exit code $rc, wanted 0"; fi
if ! grep -qF -- "$fragment" <<<"$out"; then fail "output does not contain '$fragment'"; fi
row=$(grep -F "per stage (us/call" <<<"$out") || fail "no per-stage row"
# "... | f 1.242 [9.9] | u 0.982 [7.9] | u' contact 0.130 [1.0] | render write 1.552 [12.4]"
check=$(awk '{
  for (i = 1; i < NF; ++i) {
    if ($i == "f") f = $(i + 1); else if ($i == "u") u = $(i + 1)
    else if ($i == "contact") c = $(i + 1); else if ($i == "write") r = $(i + 1)
  }
  ok = 1
  if (f !~ /^[0-9.]+(e[-+]?[0-9]+)?$/ || f + 0 <= 0) ok = 0
  if (u !~ /^[0-9.]+(e[-+]?[0-9]+)?$/ || u + 0 <= 0) ok = 0
  if (r !~ /^[0-9.]+(e[-+]?[0-9]+)?$/ || r + 0 <= 0) ok = 0
  if (c !~ /^[0-9.]+(e[-+]?[0-9]+)?$/) ok = 0
  print ok ? "ok" : "bad f=" f " u=" u " contact=" c " render=" r
}' <<<"$row")
[ "$check" = ok ] || fail "stage times not finite and positive: $check"
echo "ok: exit 0, '$fragment', $row"
