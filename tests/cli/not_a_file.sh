#!/usr/bin/env bash
# not_a_file.sh EXPECT_EXIT SOFTTLED DATA
# Inputs that are not regular files: a FIFO (it must be refused at once, not block on
# open), a directory and a device, as a scene file, as a body.file and as mesh --surface.
set -u
here=$(cd "$(dirname "$0")" && pwd)
expect=$1 exe=$2 data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkfifo "$tmp/fifo.toml" "$tmp/fifo.obj"
mkdir "$tmp/dir.obj"
status=0
check() { SOFTTLED_CLI_TIMEOUT=20 bash "$expect" "$@" || status=1; }
check 2 "scene file $tmp/fifo.toml: not a regular file (a FIFO)" "$exe" run --scene "$tmp/fifo.toml"
check 2 "scene file $tmp/dir.obj: not a regular file (a directory)" "$exe" run --scene "$tmp/dir.obj"
check 2 "scene file /dev/null: not a regular file (a character device)" "$exe" mesh --scene /dev/null
check 2 "body.file: $tmp/fifo.obj: not a regular file (a FIFO)" "$exe" run --scene "$data/surface.toml" --set "body.file=$tmp/fifo.obj"
check 2 "body.file: $tmp/dir.obj: not a regular file (a directory)" "$exe" run --scene "$data/surface.toml" --set "body.file=$tmp/dir.obj"
check 2 "body.file: /dev/null: not a regular file (a character device)" "$exe" run --scene "$data/surface.toml" --set body.file=/dev/null
check 2 "$tmp/fifo.obj: not a regular file (a FIFO)" "$exe" mesh --surface "$tmp/fifo.obj"
check 2 "$tmp/dir.obj: not a regular file (a directory)" "$exe" mesh --surface "$tmp/dir.obj"
# An output FIFO nobody reads is refused after 5 s (open(2) would block for good, and a
# signal could not stop it); with a reader the rows go through it.
mkfifo "$tmp/rows.csv"
check 5 "$tmp/rows.csv: cannot write: a FIFO with no reader after 5 s (start its reader first)" "$exe" run --scene "$data/surface.toml" --set time.duration=0.002 --csv "$tmp/rows.csv"
timeout 60 cat "$tmp/rows.csv" >"$tmp/read.csv" &
reader=$!
check 0 "wrote 3 CSV rows to $tmp/rows.csv" "$exe" run --scene "$data/surface.toml" --set time.duration=0.002 --csv "$tmp/rows.csv"
wait $reader
if [ "$(head -c 2 "$tmp/read.csv")" != "t," ] || [ "$(wc -l <"$tmp/read.csv")" -ne 4 ]; then
  echo "FAIL: the reader got $(wc -l <"$tmp/read.csv") lines, not the header and 3 rows"
  status=1
fi
# Size caps: a scene file above 4 MiB is refused before it is read.
head -c 5000000 /dev/zero | tr '\0' '#' >"$tmp/big.toml"
check 2 "scene file $tmp/big.toml: 5000000 bytes, above the limit of 4194304 bytes" "$exe" run --scene "$tmp/big.toml"
exit $status
