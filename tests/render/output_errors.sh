#!/usr/bin/env bash
# `softtled plot` and `softtled render` on bad input and failing outputs: exit code 2 (bad
# input) or 5 (resource: write failed), a message naming the problem, and no broken file.
#  - PNG write errors (file size limit -> EFBIG, /dev/full) exit 5 and leave the old file intact
#  - plot --out a device / FIFO is written in place, never replaced by a regular file
#  - plot's CSV: directories, devices, FIFOs refused; NaN / inf / huge / hex / NUL refused
#    naming row and column; a UTF-8 BOM accepted
#  - --size that would wrap an int, duplicate or colliding --at times, a --stem with '/'
#  - render --video when ffmpeg exits 0 after a failed write: exit 5, no file left
# Usage: output_errors.sh SOFTTLED EXPECT_EXIT ASSETS OUT_DIR. The parts needing EGL or
# ffmpeg are skipped (with a line saying so) where those are missing.
set -u
exe=$1 expect=$2 assets=$3 out=$4
rm -rf "$out" && mkdir -p "$out"
nfail=0
check() { bash "$expect" "$@" || nfail=$((nfail + 1)); }
bad() { echo "FAIL: $*"; nfail=$((nfail + 1)); }
limited=(bash -c 'trap "" XFSZ; ulimit -f 4; exec "$@"' _)  # writes past 4 KiB fail with EFBIG

csv="$out/ok.csv"
{
  echo "t,cx,cy,cz,min_gap,ke,se,pe,n_contact"
  for i in 0 1 2 3 4 5; do echo "0.0$i,0,0.01$i,0,0,${i}e-6,1e-6,0.001,0"; done
} >"$csv"

# 1. PNG write errors: exit 5, the message names the file and the reason; the old file stays
echo "old contents" >"$out/keep.png"
check 5 "keep.png: write failed: File too large" "${limited[@]}" "$exe" plot "$csv" --out "$out/keep.png"
[ "$(cat "$out/keep.png")" = "old contents" ] || bad "plot: a failed write changed keep.png"
[ -e "$out/keep.png.tmp" ] && bad "plot: keep.png.tmp left behind"
check 5 "No space left on device" "$exe" plot "$csv" --out /dev/full
[ -c /dev/full ] || bad "/dev/full is no longer a device"
check 0 "rows ->" "$exe" plot "$csv" --out /dev/null
[ -c /dev/null ] || bad "/dev/null is no longer a device"
# A file plot creates is named for its contents (it wrote PNG data into x.jpg).
check 2 "writes a PNG; give a name ending in .png" "$exe" plot "$csv" --out "$out/x.jpg"
[ -e "$out/x.jpg" ] && bad "plot: x.jpg written"

# 3. plot --out a FIFO: written in place (a reader gets the PNG), still a FIFO afterwards
mkfifo "$out/out.fifo"
cat "$out/out.fifo" >"$out/from_fifo.png" &
reader=$!
check 0 "rows ->" "$exe" plot "$csv" --out "$out/out.fifo"
wait $reader
[ -p "$out/out.fifo" ] || bad "plot replaced the FIFO with a regular file"
[ "$(head -c 4 "$out/from_fifo.png" | tail -c 3)" = "PNG" ] || bad "the FIFO's reader got no PNG"

# 4. plot's input: only regular files (a FIFO must not hang: expect_exit has a timeout)
mkfifo "$out/in.fifo"
SOFTTLED_CLI_TIMEOUT=20 check 2 "not a regular file (a FIFO" "$exe" plot "$out/in.fifo" --out "$out/x.png"
check 2 "not a regular file (a character device)" "$exe" plot /dev/zero --out "$out/x.png"
check 2 "not a regular file (a directory)" "$exe" plot "$out" --out "$out/x.png"
check 2 "No such file" "$exe" plot "$out/missing.csv" --out "$out/x.png"

# 5. plot's numbers: finite decimals only, naming line, row and column
header="t,cx,cy,cz,min_gap,ke,se,pe,n_contact"
for v in nan NaN inf -inf infinity 1e999 1e31 0x10 1,5 " 1 2" 1e 1e+ . -; do
  printf '%s\n0,0,0.01,0,0,0,0,0.001,0\n0.01,0,0.01,0,0,%s,0,0.001,0\n' "$header" "$v" >"$out/bad.csv"
  case $v in
    1,5) want="10 values, the header has 9" ;;
    1e999 | 1e31 | inf | -inf | infinity | nan | NaN) want="bad.csv:3 (row 2): column ke: '$v' is not" ;;
    *) want="bad.csv:3 (row 2): column ke: '$v' is not a decimal number" ;;
  esac
  check 2 "$want" "$exe" plot "$out/bad.csv" --out "$out/x.png"
done
printf '%s\n0,0,0.01,0,0,0,0,0.001,0\n0.01,0,0.01,0,0,1e31,0,0.001,0\n' "$header" >"$out/big.csv"
check 2 "column ke: '1e31' is not a finite number of magnitude at most 1e30" "$exe" plot "$out/big.csv" --out "$out/x.png"
printf '%s\n0,0,0.01,0,0,0,0,0.001,0\n0.01,0,0.01,0,0,1\0002,0,0.001,0\n' "$header" >"$out/nul.csv"
check 2 "nul.csv:3: a NUL byte" "$exe" plot "$out/nul.csv" --out "$out/x.png"
printf '\357\273\277%s\n0,0,0.01,0,0,0,0,0.001,0\n0.01,0,0.012,0,0,1e-6,0,0.0009,0\n' "$header" >"$out/bom.csv"
check 0 "bom.csv: 2 rows" "$exe" plot "$out/bom.csv" --out "$out/bom.png"
[ -s "$out/bom.png" ] || bad "bom.csv: no PNG"
[ -e "$out/x.png" ] && bad "a refused plot wrote x.png"

# 7. --size that wraps an int
check 2 "--size '4294968196x700'" "$exe" plot "$csv" --out "$out/x.png" --size 4294968196x700
check 2 "--size '900x-700'" "$exe" plot "$csv" --out "$out/x.png" --size 900x-700
scene="$assets/scenes/torus_drop.toml"
common=(--scene "$scene" --set 'body.segments=[45,9]' --size 200x150)
check 2 "--size '4294967360x64'" "$exe" render --scene "$scene" --at 0.001 --size 4294967360x64 --out "$out/r"

# 6. duplicate and colliding --at times; 8. --stem with '/' (all refused before simulating)
check 2 "time 0.001 given twice" "$exe" render "${common[@]}" --at 0.001,0.001 --out "$out/r"
check 2 "both give the file name torus_drop_t0.0010.png" "$exe" render "${common[@]}" --at 0.00101,0.00102,0.00103 --out "$out/r"
check 2 "--stem 'sub/x': must be a file name stem without '/'" "$exe" render "${common[@]}" --at 0.001 --stem sub/x --out "$out/r"
check 2 "--stem '../escaped'" "$exe" render "${common[@]}" --at 0.001 --stem ../escaped --out "$out/r"
check 2 "--stem '..'" "$exe" render "${common[@]}" --at 0.001 --stem .. --out "$out/r"
[ -e "$out/escaped_t0.0010.png" ] && bad "--stem ../escaped wrote outside --out"
[ -e "$out/r" ] && bad "a refused render created --out"
# a later frame's name taken by a directory: refused before meshing, no earlier frame written
mkdir -p "$out/rd/torus_drop_t0.0020.png"
check 2 "--out $out/rd/torus_drop_t0.0020.png: is a directory" "$exe" render "${common[@]}" --at 0.001,0.002 --out "$out/rd"
[ -e "$out/rd/torus_drop_t0.0010.png" ] && bad "a render refused for its second frame wrote the first"

# render's PNG and video writes on a full disk (need EGL; the video also ffmpeg)
"$exe" render "${common[@]}" --at 0 --out "$out/egl" >"$out/egl.txt" 2>&1
if [ $? -ne 0 ] && grep -q -e "no EGL display" -e "no EGL backend" "$out/egl.txt"; then
  echo "no offscreen OpenGL (EGL): render write failures not checked"
else
  check 5 "File too large" "${limited[@]}" "$exe" render "${common[@]}" --at 0,0.001 --out "$out/rf"
  [ -n "$(ls -A "$out/rf" 2>&1)" ] && bad "render left files after a failed write: $(ls "$out/rf")"
  if command -v ffmpeg >/dev/null; then
    check 5 "File too large" "${limited[@]}" "$exe" render "${common[@]}" --color displacement --video "$out/v.mp4" --to 0.1
    [ -e "$out/v.mp4" ] || [ -e "$out/v.mp4.tmp" ] && bad "render --video left a file after a failed write"
    # an ffmpeg that exits 0 without a message but leaves a cut MP4
    mkdir -p "$out/fakebin"
    printf '#!/bin/sh\nfor last; do :; done\ncat >/dev/null\nprintf "\\000\\000\\001\\000ftypisom" >"$last"\nexit 0\n' >"$out/fakebin/ffmpeg"
    chmod +x "$out/fakebin/ffmpeg"
    check 5 "incomplete: box 'ftyp' at byte 0 runs past the end" env PATH="$out/fakebin:$PATH" "$exe" render "${common[@]}" \
      --video "$out/cut.mp4" --to 0.05
    [ -e "$out/cut.mp4" ] || [ -e "$out/cut.mp4.tmp" ] && bad "render --video left the cut video"
  else
    echo "no ffmpeg: render --video write failure not checked"
  fi
fi

[ $nfail -eq 0 ] || { echo "FAIL: $nfail checks failed"; exit 1; }
echo "PASS"
