#!/usr/bin/env bash
# output_aliases.sh EXPECT_EXIT SOFTTLED DATA
# Every file a command writes is compared with every input and output by device and inode
# or resolved path, not by the name given: a name in run's --vtu directory (series.pvd, a
# frame) that is a symlink to the scene or to the run's --csv, or a hard link to the scene,
# a --csv that is a dangling symlink to a frame, a scene that is a symlink into the
# directory; render --at's PNG names in --out that are a symlink to the scene or to
# another frame, a scene named like a frame's NAME.tmp. Each is refused (exit 2) before
# meshing and the user's files stay byte for byte (each was replaced or deleted, exit 0).
# And paths longer than PATH_MAX once the names written on the way are added (NAME.tmp, a
# frame in --vtu DIR) are refused up front, the message ending in the reason (they failed
# after the work, exit 5, the reason cut off the message).
set -u
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cp "$data/surface.toml" "$data/tetrahedron.obj" .
cp surface.toml t.toml
status=0
t() { bash "$expect" "$@" || status=1; }
has() { "$exe" "$1" --help >/dev/null 2>&1; }
same() { cmp -s "$1" "$2" || { echo "FAIL: $3 ($2 changed)"; status=1; }; }
printf 't,cx\n0,1\n' > a.csv && cp a.csv a0.csv

# Symlinks inside the --vtu directory under the names the series writes.
mkdir d1 d2 d3 && ln -s ../t.toml d1/series.pvd && ln -s ../t.toml d2/frame_00003.vtu &&
  ln -s ../a.csv d3/frame_00000.vtu
link="is not a regular file (a symbolic link to"
t 2 "d1/series.pvd $link ../t.toml" "$exe" run --scene t.toml --vtu d1
t 2 "d2/frame_00003.vtu $link ../t.toml" "$exe" run --scene t.toml --vtu d2
t 2 "d3/frame_00000.vtu $link ../a.csv" "$exe" run --scene t.toml --vtu d3 --csv a.csv
same surface.toml t.toml "the scene replaced through a symlink in --vtu"
same a0.csv a.csv "the CSV replaced through a symlink in --vtu"
{ [ -L d1/series.pvd ] && [ -L d2/frame_00003.vtu ] && [ -L d3/frame_00000.vtu ]; } ||
  { echo "FAIL: a link was replaced"; status=1; }
# A hard link to the scene there (same inode), a --csv that is a dangling link to a frame
# (creating it), a scene that is a link to a frame in the directory.
mkdir d4 d5 d6 && ln t.toml d4/frame_00001.vtu && ln -s d5/frame_00002.vtu c.csv && cp t.toml d6/frame_00002.vtu &&
  ln -s d6/frame_00002.vtu sc.toml
writes="in that directory, overwriting the"
t 2 "--vtu d4 and --scene t.toml: --vtu writes frame_00001.vtu $writes input" "$exe" run --scene t.toml --vtu d4
t 2 "--csv c.csv and --vtu d5: --vtu writes frame_00002.vtu $writes other output" \
  "$exe" run --scene t.toml --vtu d5 --csv c.csv
t 2 "--vtu d6 and --scene sc.toml: --vtu writes frame_00002.vtu $writes input" "$exe" run --scene sc.toml --vtu d6
same surface.toml t.toml "the scene changed through a hard link in --vtu"
same surface.toml d6/frame_00002.vtu "the scene behind a link into --vtu changed"
[ -z "$(ls d5)" ] || { echo "FAIL: d5 written: $(ls d5)"; status=1; }
# Control: a directory holding an earlier series of regular files runs.
t 0 "simulated" "$exe" run --scene t.toml --vtu d7 --csv b.csv
t 0 "simulated" "$exe" run --scene t.toml --vtu d7 --csv b.csv

if has render; then
  # A PNG name in --out that is a symlink to the scene (the scene became a PNG), a scene
  # named like a frame's temporary (removed as a leftover), two frames one file.
  mkdir -p r1/out r2 r3 && cp t.toml tetrahedron.obj r1/ && cp t.toml r2/s_t0.0100.png.tmp && cp tetrahedron.obj r2/ &&
    ln -s ../s.toml r1/out/s_t0.0100.png && cp t.toml r1/s.toml && : > r3/x_t0.0200.png &&
    ln -s x_t0.0200.png r3/x_t0.0100.png
  render=("$exe" render --size 64x64 --backend cpu)
  t 2 "--out r1/out/s_t0.0100.png and --scene r1/s.toml are the same file" \
    "${render[@]}" --scene r1/s.toml --at 0.01 --out r1/out
  t 2 "--out is written to r2/s_t0.0100.png.tmp first, which is the input" \
    "${render[@]}" --scene r2/s_t0.0100.png.tmp --at 0.01 --out r2 --stem s
  t 2 "--out r3/x_t0.0100.png and --out r3/x_t0.0200.png are the same file" \
    "${render[@]}" --scene t.toml --at 0.01,0.02 --out r3 --stem x
  same surface.toml r1/s.toml "render wrote a PNG onto its scene through a link in --out"
  same surface.toml r2/s_t0.0100.png.tmp "render removed its scene as a frame's leftover temporary"
fi

# Paths that fit PATH_MAX (4096 with the NUL) themselves but not with what is written on
# the way. A directory of 4021 characters made of 200-character components.
cp surface.toml l.toml
deep=.
for _ in $(seq 20); do deep=$deep/$(printf 'd%.0s' $(seq 200)); done
mkdir -p "$deep"
base=$deep/$(printf 'w%.0s' $(seq 66))  # BASE.node: 4093 characters, BASE.node.tmp 4097
vtu=$deep/$(printf 'v%.0s' $(seq 60))  # 4082 characters; its frames' temporaries beyond 4095
for args in "mesh --scene l.toml --write $base" "run --scene l.toml --vtu $vtu" \
            "run --scene l.toml --csv a.csv --vtu $vtu"; do
  out=$("$exe" $args 2>&1)
  rc=$?
  { [ $rc -eq 2 ] && grep -q "above the system's limit of 4095 (File name too long); give a shorter path$" <<<"$out" &&
    ! grep -q "^mesh:\|Mesh tetrahedra" <<<"$out"; } ||
    { echo "FAIL: ${args%% --*}, a path past PATH_MAX: exit $rc, wanted 2 before meshing"; tail -c 300 <<<"$out"
      status=1; }
done
same a0.csv a.csv "the CSV of a run refused for its --vtu path"
[ -z "$(ls "$deep")" ] || { echo "FAIL: files written under the long path: $(ls "$deep")"; status=1; }
# A message longer than the 2000 characters kept: its end (the reason) stays.
out=$("$exe" run --scene "$deep/$(printf 'n%.0s' $(seq 60)).toml" 2>&1)
grep -q "characters cut) ... .*: cannot open file: No such file or directory$" <<<"$out" ||
  { echo "FAIL: a long message lost its reason: $(tail -c 300 <<<"$out")"; status=1; }
[ $status -eq 0 ] && echo "ok: aliases through links refused, inputs unchanged; long paths refused up front"
exit $status
