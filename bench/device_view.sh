#!/usr/bin/env bash
# The viewer in a GLX window on the GPU machine, driven as a person would (xdotool): pull
# the torus, switch friction twice (F), tilt the slope (] ]), take screenshots (P), quit.
# Needs a build in /tmp/build (bench/device_run.sh . build) and .glx/ from
# bench/pack_x_debs.sh; writes view.log, xvfb.log and the PNGs to $OUT. The viewer logs
# which way its vertices go (interop) and its rates (fps, steps/s, real-time factor).
# VIEW_EL=T4|T4ANP (default T4ANP), VIEW_DT=adaptive|auto (default adaptive).
set -u
B=/tmp/build; OUTD=${OUT:-/tmp/out}; mkdir -p "$OUTD"
XG=/tmp/xg; mkdir -p $XG /tmp/xlibs /var/lib/xkb
for f in .glx/*.deb; do dpkg -x "$f" $XG; done
L=$XG/usr/lib/x86_64-linux-gnu
for so in $(cd $L && ls *.so.* 2>/dev/null); do ldconfig -p | grep -q "[[:space:]]$so " || ln -sf "$L/$so" /tmp/xlibs/$so; done
mkdir -p /usr/lib/x86_64-linux-gnu/dri && cp -n $L/dri/swrast_dri.so /usr/lib/x86_64-linux-gnu/dri/ 2>/dev/null
[ -x /usr/bin/xkbcomp ] || cp $XG/usr/bin/xkbcomp /usr/bin/
export LD_LIBRARY_PATH=/tmp/xlibs:${LD_LIBRARY_PATH:-}
export LIBGL_DRIVERS_PATH=$L/dri
$XG/usr/bin/Xvfb :99 -screen 0 1280x800x24 -xkbdir $XG/usr/share/X11/xkb -nolisten tcp > $OUTD/xvfb.log 2>&1 &
XPID=$!
sleep 2
export DISPLAY=:99 __GLX_VENDOR_LIBRARY_NAME=nvidia
log=$OUTD/view.log
$B/softtled view --backend cuda --size 1280x800 --scene assets/scenes/torus_drop.toml --set time.dt=${VIEW_DT:-adaptive} \
  material.element=${VIEW_EL:-T4ANP} --screenshot-dir $OUTD --quit-after 60 > $log 2>&1 &
pid=$!
for i in $(seq 300); do grep -q "first frame drawn" $log && break; kill -0 $pid 2>/dev/null || break; sleep 0.1; done
if ! grep -q "first frame drawn" $log; then echo "NO FRAME"; cat $log; tail -20 $OUTD/xvfb.log; kill $XPID; exit 1; fi
sleep 4
XD=$XG/usr/bin/xdotool
$XD key p; sleep 1
png=$(ls $OUTD/softtled_view_*.png | head -1)
read bx0 by0 bx1 by1 < <($B/tests/render/png_probe "$png" 380 0 1280 550 | sed -n 's/^body_bbox=//p' | tr , ' ')
echo "body bbox: ${bx0:-none} ${by0:-} ${bx1:-} ${by1:-}"
if [ -n "${bx0:-}" ]; then
  x=$(( bx0 + (bx1 - bx0) / 12 )); y=$(( (by0 + by1) / 2 ))
  $XD mousemove $x $y mousedown 1; sleep 0.3; $XD mousemove $x $(( y - 60 )); sleep 1.5; $XD mouseup 1
fi
$XD mousemove 1000 100
sleep 3; $XD key f; sleep 3; $XD key f; sleep 3
$XD key bracketright; sleep 0.3; $XD key bracketright; sleep 6
$XD key p; sleep 1
$XD key Escape
for i in $(seq 100); do kill -0 $pid 2>/dev/null || break; sleep 0.1; done
kill $pid 2>/dev/null; kill $XPID 2>/dev/null
cat $log
ls -la $OUTD/*.png; sha256sum $OUTD/*.png
