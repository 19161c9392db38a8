#!/usr/bin/env bash
# expect_exit.sh CODE FRAGMENT PROGRAM [ARGS...]
# Runs PROGRAM ARGS; passes when it exits with CODE, prints FRAGMENT (fixed string, on
# stdout or stderr) and, for CODE 2 and 5, the one-line "softtled: error:" message. Fails
# on a signal (exit >= 128: crash, abort, sanitizer abort), a hang (timeout) or another
# code. SOFTTLED_CLI_ABSENT: a fixed string that must not appear in the output.
set -u
want=$1 fragment=$2
shift 2
out=$(timeout "${SOFTTLED_CLI_TIMEOUT:-240}" "$@" 2>&1)
rc=$?
fail() {
  echo "FAIL: $*"
  echo "command: $CMD"
  echo "exit code: $rc (wanted $want)"
  echo "---- output ----"
  printf '%s\n' "$out" | tail -n 60
  exit 1
}
CMD=$(printf '%q ' "$@")
if [ "$rc" -eq 124 ]; then fail "hung (timeout)"; fi
if [ "$rc" -ge 128 ]; then fail "killed by signal $((rc - 128)) (crash)"; fi
if [ "$rc" -ne "$want" ]; then fail "wrong exit code"; fi
if ! grep -qF -- "$fragment" <<<"$out"; then fail "output does not contain '$fragment'"; fi
if { [ "$want" -eq 2 ] || [ "$want" -eq 5 ]; } && ! grep -q '^softtled: error: ' <<<"$out"; then fail "no 'softtled: error:' line"; fi
if [ -n "${SOFTTLED_CLI_ABSENT:-}" ] && grep -qF -- "$SOFTTLED_CLI_ABSENT" <<<"$out"; then
  fail "output contains '$SOFTTLED_CLI_ABSENT'"
fi
echo "ok: exit $rc, '$fragment'"
