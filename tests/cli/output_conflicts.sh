#!/usr/bin/env bash
# output_conflicts.sh EXPECT_EXIT SOFTTLED DATA
# An output onto an input or onto another output is refused before anything is written
# (exit 2 naming both flags), and the input is left byte for byte as it was: run --csv
# onto the scene or its surface (also through a symlink), bench --json and mesh --vtu /
# --write onto the scene, run --csv onto the series.pvd or a frame of its own --vtu
# directory, --csv and --vtu the same path. An existing writable file in a read-only
# directory is refused up front for an atomic (replaced) output.
set -u
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
chmod 755 "$tmp"
trap 'chmod -R u+w "$tmp"; rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cp "$data/surface.toml" "$data/tetrahedron.obj" .
sum0=$(cat surface.toml tetrahedron.obj | md5sum)
status=0
t() { bash "$expect" "$@" || status=1; }
# plot and render exist in builds with the renderer only (not in the sanitizer build).
has() { "$exe" "$1" --help >/dev/null 2>&1; }
t 2 "--csv surface.toml and --scene surface.toml are the same file" "$exe" run --scene surface.toml --csv surface.toml
t 2 "--csv tetrahedron.obj and body.file" "$exe" run --scene surface.toml --csv tetrahedron.obj
ln -s surface.toml link.toml
t 2 "--csv link.toml and --scene surface.toml are the same file" "$exe" run --scene surface.toml --csv link.toml
t 2 "--json surface.toml and --scene surface.toml are the same file" "$exe" bench --scene surface.toml --steps 30 --samples 3 --json surface.toml
t 2 "--vtu surface.toml and --scene surface.toml are the same file" "$exe" mesh --scene surface.toml --vtu surface.toml
t 2 "--vtu tetrahedron.obj and --surface tetrahedron.obj are the same file" "$exe" mesh --surface tetrahedron.obj --vtu tetrahedron.obj
t 2 "--write surface.toml.node" "$exe" mesh --scene surface.toml --write surface.toml --vtu surface.toml.node
t 2 "--csv same.csv and --vtu same.csv are the same file" "$exe" run --scene surface.toml --csv same.csv --vtu same.csv
[ -e same.csv ] && { echo "FAIL: same.csv created"; status=1; }
# A video is renamed onto its name from NAME.tmp: a FIFO or a symlink to a device there was
# replaced by a regular file (exit 0), its reader left waiting.
if has render; then
  mkfifo fifo.mp4 && ln -s /dev/null null.mp4
  t 2 "--video fifo.mp4: is a FIFO" "$exe" render --scene surface.toml --video fifo.mp4 --to 0.01 --backend cpu
  t 2 "--video null.mp4: is a special file" "$exe" render --scene surface.toml --video null.mp4 --to 0.01 --backend cpu
  { [ -p fifo.mp4 ] && [ -L null.mp4 ] && [ -c /dev/null ]; } || { echo "FAIL: a special file at the video's name was replaced"; status=1; }
fi
mkdir v1
t 2 "--csv v1/series.pvd and --vtu v1: --vtu writes series.pvd in that directory" "$exe" run --scene surface.toml --csv v1/series.pvd --vtu v1
t 2 "--vtu writes frame_00002.vtu in that directory" "$exe" run --scene surface.toml --csv ./v1/frame_00002.vtu --vtu v1/
[ -z "$(ls v1)" ] || { echo "FAIL: v1 not empty: $(ls v1)"; status=1; }
[ "$(cat surface.toml tetrahedron.obj | md5sum)" = "$sum0" ] || { echo "FAIL: an input was changed"; status=1; }
# Controls: distinct outputs run.
t 0 "simulated" "$exe" run --scene surface.toml --csv out.csv --vtu v1
[ "$(grep -c '<DataSet' v1/series.pvd)" -ge 2 ] && [ "$(wc -l <out.csv)" -ge 3 ] || { echo "FAIL: control outputs"; status=1; }
# The other inputs and commands: the second half of a TetGen .node/.ele body, the CSV that
# plot reads, the scene under render's --video or under one of its PNG frames.
t 0 "Mesh tetrahedra" "$exe" mesh --surface tetrahedron.obj --write tt
printf 'units = "mm"\n[body]\nshape = "tet_file"\nfile = "tt.node"\nposition = [0, -10, 0]\n[time]\nduration = 0.002\n' > tfs.toml
sum1=$(cat tt.node tt.ele out.csv | md5sum)
t 2 "--csv tt.ele and body.file tt.ele are the same file" "$exe" run --scene tfs.toml --csv tt.ele
t 2 "--vtu tt.ele and body.file tt.ele are the same file" "$exe" mesh --scene tfs.toml --vtu tt.ele
has plot && t 2 "--out out.csv and csv out.csv are the same file" "$exe" plot out.csv --out out.csv
[ "$(cat tt.node tt.ele out.csv | md5sum)" = "$sum1" ] || { echo "FAIL: a .node/.ele or the plotted CSV was changed"; status=1; }
mkdir rs && cp surface.toml rs/x_t0.0000.png && cp tetrahedron.obj rs/ && cp surface.toml sc.mkv
sum2=$(cat rs/x_t0.0000.png sc.mkv | md5sum)
has render && t 2 "--out rs/x_t0.0000.png" "$exe" render --scene rs/x_t0.0000.png --out rs --stem x --at 0 --backend cpu
if has render && command -v ffmpeg >/dev/null; then
  t 2 "--video sc.mkv and --scene sc.mkv are the same file" "$exe" render --scene sc.mkv --video sc.mkv --to 0.05 --backend cpu
fi
[ "$(cat rs/x_t0.0000.png sc.mkv | md5sum)" = "$sum2" ] || { echo "FAIL: render overwrote its scene"; status=1; }
# Onto the file or pipe standard output goes to: the summary would mix with the output.
"$exe" run --scene surface.toml --csv so.txt > so.txt 2> so.err
rc=$?; { [ $rc -eq 2 ] && grep -q "is where standard output goes" so.err; } || { echo "FAIL: --csv onto stdout's file (exit $rc)"; status=1; }
out=$("$exe" run --scene surface.toml --csv /dev/stdout 2>&1 | cat)
grep -q "is where standard output goes" <<<"$out" || { echo "FAIL: --csv /dev/stdout into a pipe: $out"; status=1; }
# The same for standard error (the messages, the watchdog's among them): --csv f 2> f,
# --csv /dev/stderr (opening it truncated the lines written), the other outputs onto the
# file standard error goes to, and standard error into --vtu's index or into an input.
"$exe" run --scene surface.toml --csv se.csv 2> se.csv
rc=$?; { [ $rc -eq 2 ] && grep -q "^softtled: error: --csv se.csv: is where standard error goes" se.csv && [ "$(wc -l <se.csv)" -eq 1 ]; } ||
  { echo "FAIL: --csv onto stderr's file (exit $rc): $(head -c 300 se.csv)"; status=1; }
"$exe" run --scene surface.toml --csv /dev/stderr 2> se2.csv
rc=$?; { [ $rc -eq 2 ] && grep -q "is where standard error goes" se2.csv; } || { echo "FAIL: --csv /dev/stderr (exit $rc)"; status=1; }
out=$("$exe" run --scene surface.toml --csv /dev/stderr 2>&1 >/dev/null | cat)
grep -q "is where standard error goes" <<<"$out" || { echo "FAIL: --csv /dev/stderr into a pipe: $out"; status=1; }
"$exe" mesh --scene surface.toml --vtu se.vtu 2> se.vtu
rc=$?; { [ $rc -eq 2 ] && grep -q "^softtled: error: --vtu se.vtu: is where standard error goes" se.vtu; } || { echo "FAIL: mesh --vtu onto stderr's file (exit $rc)"; status=1; }
"$exe" mesh --scene surface.toml --write se 2> se.node
rc=$?; { [ $rc -eq 2 ] && grep -q "^softtled: error: --write se.node: is where standard error goes" se.node; } || { echo "FAIL: mesh --write onto stderr's file (exit $rc)"; status=1; }
"$exe" bench --scene surface.toml --steps 30 --samples 3 --json se.json 2> se.json
rc=$?; { [ $rc -eq 2 ] && grep -q "^softtled: error: --json se.json: is where standard error goes" se.json; } || { echo "FAIL: bench --json onto stderr's file (exit $rc)"; status=1; }
mkdir v2
"$exe" run --scene surface.toml --vtu v2 2> v2/series.pvd
rc=$?; { [ $rc -eq 2 ] && grep -q "standard error goes to v2/series.pvd, which this output writes; send standard error elsewhere" v2/series.pvd; } ||
  { echo "FAIL: stderr into --vtu's index (exit $rc)"; status=1; }
# Appended (2>>) onto a file that holds something, the refusal must not land in it: the
# scene, an earlier CSV given as --csv, an earlier series' index (each had the error line
# appended, which left the scene unparsable, the CSV ragged and the index broken XML).
cp surface.toml app2.toml
setsid "$exe" run --scene app2.toml --csv se3.csv 2>> app2.toml < /dev/null
rc=$?; { [ $rc -eq 2 ] && cmp -s surface.toml app2.toml && [ ! -e se3.csv ]; } ||
  { echo "FAIL: stderr appended onto the scene (exit $rc): $(tail -c 200 app2.toml)"; status=1; }
# Both streams appended onto the scene (>> f 2>&1), and commands that had no check of the
# scene against standard error (render's PNGs, bench): the scene stays as it was.
setsid "$exe" run --scene app2.toml >> app2.toml 2>&1 < /dev/null
rc=$?; { [ $rc -eq 2 ] && cmp -s surface.toml app2.toml; } || { echo "FAIL: >> scene 2>&1 (exit $rc)"; status=1; }
for cmd in "render --out r2 --at 0" "bench --steps 30 --samples 3" "mesh"; do
  has ${cmd%% *} || continue
  setsid "$exe" $cmd --scene app2.toml 2>> app2.toml < /dev/null
  rc=$?; { [ $rc -eq 2 ] && cmp -s surface.toml app2.toml; } || { echo "FAIL: $cmd 2>> scene (exit $rc)"; status=1; }
done
printf 't,cx\n0,1\n' > keep.csv && cp keep.csv keep0.csv
setsid "$exe" run --scene surface.toml --csv keep.csv 2>> keep.csv < /dev/null
rc=$?; { [ $rc -eq 2 ] && cmp -s keep0.csv keep.csv; } || { echo "FAIL: stderr appended onto --csv's file (exit $rc)"; status=1; }
"$exe" run --scene surface.toml --vtu v3 2> /dev/null && cp v3/series.pvd pvd0
setsid "$exe" run --scene surface.toml --vtu v3 2>> v3/series.pvd < /dev/null
rc=$?; { [ $rc -eq 2 ] && cmp -s pvd0 v3/series.pvd; } || { echo "FAIL: stderr appended onto --vtu's index (exit $rc)"; status=1; }
# Control: standard error to another file.
"$exe" run --scene surface.toml --csv ctl.csv 2> ctl.err
rc=$?; { [ $rc -eq 0 ] && [ "$(wc -l <ctl.csv)" -ge 3 ] && ! grep -q error ctl.err; } || { echo "FAIL: control, stderr elsewhere (exit $rc)"; status=1; }
# The names written on the way: PATH.tmp of a replaced output, a first frame staged as
# .new beside an earlier series; and standard output sent into a file that is an input or
# that --vtu writes. Each was consumed (the scene gone) or lost (the CSV) with exit 0.
cp surface.toml out.vtu.tmp && cp surface.toml b.json.tmp
t 2 "--vtu out.vtu and --scene out.vtu.tmp: --vtu is written to out.vtu.tmp first, which is the input" "$exe" mesh --scene out.vtu.tmp --vtu out.vtu
t 2 "--json b.json and --scene b.json.tmp" "$exe" bench --scene b.json.tmp --steps 30 --samples 3 --json b.json
[ "$(cat out.vtu.tmp b.json.tmp | md5sum)" = "$(cat surface.toml surface.toml | md5sum)" ] || { echo "FAIL: a scene named NAME.tmp was overwritten"; status=1; }
t 2 "--vtu writes frame_00000.vtu.new in that directory" "$exe" run --scene surface.toml --csv v1/frame_00000.vtu.new --vtu v1
"$exe" run --scene surface.toml --vtu v1 > v1/series.pvd 2> so.err
rc=$?; { [ $rc -eq 2 ] && grep -q "standard output goes to v1/series.pvd, which this output writes" so.err; } || { echo "FAIL: stdout into --vtu's index (exit $rc)"; status=1; }
cp surface.toml app.toml && sum3=$(md5sum <app.toml)
"$exe" run --scene app.toml --csv - >> app.toml 2> so.err
rc=$?; { [ $rc -eq 2 ] && grep -q "standard output goes to app.toml, which is an input" so.err; } || { echo "FAIL: stdout appended onto the scene (exit $rc)"; status=1; }
[ "$(md5sum <app.toml)" = "$sum3" ] || { echo "FAIL: the scene was appended to"; status=1; }
t 2 "--json -: standard output is not an option here" "$exe" bench --scene surface.toml --steps 30 --samples 3 --json -
[ -e ./- ] && { echo "FAIL: a file named - was written"; status=1; }
# Read-only directory holding a writable file: the atomic replacement needs the directory.
# Run as nobody (root may write anywhere); skipped where that is not possible.
mkdir ro && touch ro/m.vtu ro/b.json && chmod 666 ro/m.vtu ro/b.json && chmod 555 ro
chmod 644 surface.toml tetrahedron.obj
asn=() ro_ok=1
if [ "$(id -u)" -eq 0 ]; then
  asn=(setpriv --reuid=65534 --regid=65534 --clear-groups)
  "${asn[@]}" test -x "$exe" 2>/dev/null || { ro_ok=0; echo "note: read-only directory cases skipped (root; $exe not usable as nobody)"; }
fi
if [ $ro_ok -eq 1 ]; then
  t 2 "--vtu ro/m.vtu: cannot replace it: cannot write in directory ro" "${asn[@]}" "$exe" mesh --scene surface.toml --vtu ro/m.vtu
  t 2 "--json ro/b.json: cannot replace it: cannot write in directory ro" "${asn[@]}" "$exe" bench --scene surface.toml --steps 30 --samples 3 --json ro/b.json
  # --csv is written in place: a writable file in a read-only directory is fine.
  touch ro2.csv; mkdir ro2 && mv ro2.csv ro2/r.csv && chmod 666 ro2/r.csv && chmod 555 ro2
  t 0 "simulated" "${asn[@]}" "$exe" run --scene surface.toml --csv ro2/r.csv
  [ ! -s ro/m.vtu ] && [ ! -s ro/b.json ] || { echo "FAIL: files in ro/ written"; status=1; }
fi
# A name the series writes taken by a directory is refused before any work (it was exit 5
# after meshing), the directory left as it was.
mkdir -p sdir/series.pvd fdir/frame_00003.vtu
t 2 "--vtu sdir: sdir/series.pvd is not a regular file (a directory)" "$exe" run --scene surface.toml --vtu sdir
t 2 "--vtu fdir: fdir/frame_00003.vtu is not a regular file (a directory)" "$exe" run --scene surface.toml --vtu fdir
[ -d sdir/series.pvd ] && [ -z "$(ls sdir/series.pvd)" ] && [ "$(ls fdir)" = frame_00003.vtu ] ||
  { echo "FAIL: sdir or fdir changed"; status=1; }
# Empty values are refused, not taken as "no output" or "the default scene".
t 2 "--csv: empty path" "$exe" run --scene surface.toml --csv ""
t 2 "--vtu: empty path" "$exe" run --scene surface.toml --vtu ""
t 2 "--scene: empty path" "$exe" run --scene ""
t 2 "--write: empty path" "$exe" mesh --scene surface.toml --write ""
t 2 "--vtu: empty path" "$exe" mesh --scene surface.toml --vtu ""
t 2 "--scene: empty path" "$exe" mesh --scene ""
t 2 "--surface: empty path" "$exe" mesh --surface ""
t 2 "--out: empty path" "$exe" accuracy --out ""
t 2 "--scene: empty path" "$exe" accuracy --scene ""
t 2 "--json: empty path" "$exe" bench --scene surface.toml --json ""
[ $status -eq 0 ] && echo "ok: conflicts, read-only directory and empty paths refused; inputs unchanged"
exit $status
