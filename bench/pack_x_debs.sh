#!/usr/bin/env bash
# Downloads (on this Debian machine) what `softtled view` needs for a GLX window on the GPU
# machine into .glx/ (ignored): Xvfb with Mesa's software GLX (which Xvfb needs to offer
# GLX at all; the client side is NVIDIA's, __GLX_VENDOR_LIBRARY_NAME=nvidia), the X
# libraries, keymaps and xdotool. Libraries the GPU image has (libc, libstdc++, libX11,
# libxcb, libxml2 with its ICU, libdrm, libedit, libelf, libLLVM of another version ...) are
# left out: ~46 MB, which fits the 64 MiB carry limit together with the tree and .gl.
# Then: run with carry [".gl", ".glx"] and `source .gl/setup.sh && bench/device_view.sh`.
set -eu
mkdir -p .git/info .glx /tmp/amd64/partial
grep -qx '/.glx/' .git/info/exclude 2>/dev/null || echo '/.glx/' >> .git/info/exclude
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
[ -n "$(ls /tmp/amd64/*Packages* 2>/dev/null)" ] || apt-get $o update -qq
skip=" gcc-12-base libc6 libgcc-s1 libstdc++6 zlib1g libexpat1 libbz2-1.0 liblzma5 libzstd1 libselinux1 libpcre2-8-0
 libsystemd0 libaudit-common libaudit1 libcap-ng0 libcap2 libgcrypt20 libgpg-error0 libuuid1 liblz4-1 libtinfo6 lsb-base
 sysvinit-utils libelogind0 libbsd0 libmd0 libpng16-16 libglvnd0 libgl1 libglx0 libicu72 libxml2 libffi8 libx11-6
 libx11-data libxau6 libxcb1 libxdmcp6 libedit2 libelf1 libdrm2 libdrm-amdgpu1 libbrotli1 "
deps=$(apt-cache $o depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks --no-replaces \
  --no-enhances --no-pre-depends xvfb xdotool libgl1-mesa-dri x11-xkb-utils xkb-data | grep -v '^[ <]' | sort -u)
cd .glx
for p in $deps; do
  [[ "$skip" == *" $p "* || "$skip" == *" $p"$'\n'* ]] && continue
  ls ${p}_*.deb >/dev/null 2>&1 || apt-get $o download -qq $p 2>/dev/null
done
du -sh . | sed 's/^/carried: /'
