#!/usr/bin/env bash
# json_text.sh SOFTTLED DATA
# bench --json quotes the scene path as a JSON string (RFC 8259) whatever it holds: a
# newline, a tab, a quote, a backslash and bytes that are not UTF-8 (escaped only quote and
# backslash, it wrote a file no JSON reader took). The file parses, and the path reads
# back with U+FFFD in place of each byte that is not UTF-8.
set -u
exe=$1 data=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
printf -v dir 'a\nb\t"q"\\\x01'
printf -v name 's\xff\xc3(\xe2\x82\xac.toml'
mkdir "$dir" && cp "$data/surface.toml" "$data/tetrahedron.obj" "$dir/" && mv "$dir/surface.toml" "$dir/$name"
"$exe" bench --scene "$dir/$name" --backend cpu --steps 30 --samples 3 --json b.json >out.txt 2>err.txt ||
  { echo "FAIL: bench exited $?"; cat err.txt; exit 1; }
python3 - <<'PY' || exit 1
import json
d = json.load(open("b.json", encoding="utf-8"))
want = 'a\nb\t"q"\\\x01/s\ufffd\ufffd(\u20ac.toml'
assert d["scene"] == want, "scene read back as %r, wanted %r" % (d["scene"], want)
PY
echo "ok: a scene path with control characters and bytes outside UTF-8 is valid JSON"
