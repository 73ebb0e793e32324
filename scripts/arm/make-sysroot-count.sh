#!/bin/sh
# A small Debian bookworm armel sysroot for scripts/arm-count.sh: libstdc++/libc
# headers, Eigen (frappe-core's pose, header-only), OpenCV core/imgproc/calib3d (for the aruco reference), libpng and
# libjpeg (the counting driver decodes the images on the guest), plus
# libopencv_aruco taken alone from libopencv-contrib406 (the package itself
# would pull Qt, HDF5, Tesseract, VTK ...). Adapted from the team's
# ../shared/tools/arm/make-sysroot.sh (the team's folder beside the
# checkout). Nothing runs inside the sysroot (mmdebstrap
# --variant=extract), so no emulation is needed to make it.
#
# usage: make-sysroot-count.sh DEST      (needs mmdebstrap and Debian's archive)
# env:   MIRROR (default: the first non-security URI of this machine's apt sources)
set -eu
DEST=$(realpath -m "${1:?usage: make-sysroot-count.sh DEST}")
SUITE=${SUITE:-bookworm}
TRIPLET=arm-linux-gnueabi
uris=$( { grep -h '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}';
          grep -h '^deb ' /etc/apt/sources.list 2>/dev/null | awk '{print $2}'; } | sort -u)
MIRROR=${MIRROR:-$(echo "$uris" | grep -v security | head -1)}
MIRROR=${MIRROR:-http://deb.debian.org/debian}
PKGS="libstdc++-12-dev libc6-dev libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev
libpng-dev libjpeg62-turbo-dev zlib1g-dev libeigen3-dev"
mkdir -p "$DEST"
# armel is not in bookworm-security any more: main + updates only.
mmdebstrap --mode=auto --variant=extract --architectures=armel \
  --include="$(echo $PKGS | tr ' ' ',')" --skip=cleanup/apt/lists \
  "$SUITE" "$DEST" "deb $MIRROR $SUITE main" "deb $MIRROR $SUITE-updates main"

# libopencv_aruco alone: download the two .debs with a private apt config
# (the host's apt state is not touched) and unpack only what aruco needs.
W="$DEST/.aruco-apt"
mkdir -p "$W/lists/partial" "$W/cache/archives/partial" "$W/debs"
echo "deb [arch=armel] $MIRROR $SUITE main" > "$W/sources.list"
touch "$W/status"
APTO="-o APT::Architecture=armel -o APT::Architectures::=armel
 -o Dir::Etc::SourceList=$W/sources.list -o Dir::Etc::SourceParts=/nonexistent
 -o Dir::State::Lists=$W/lists -o Dir::Cache=$W/cache -o Dir::State::status=$W/status"
apt-get $APTO update -qq
(cd "$W/debs" && apt-get $APTO download -qq libopencv-contrib406:armel libopencv-contrib-dev:armel)
mkdir -p "$W/x"
for d in "$W"/debs/*.deb; do dpkg-deb -x "$d" "$W/x"; done
cp -a "$W"/x/usr/lib/$TRIPLET/libopencv_aruco.so* "$DEST/usr/lib/$TRIPLET/"
cp -a "$W/x/usr/include/opencv4/opencv2/aruco" "$W/x/usr/include/opencv4/opencv2/aruco.hpp" \
      "$DEST/usr/include/opencv4/opencv2/"
rm -rf "$W"

# Extraction without maintainer scripts leaves absolute symlinks: make them relative.
find "$DEST" -type l -lname '/*' | while read -r l; do
  t=$(readlink "$l"); rel=$(realpath -m --relative-to="$(dirname "$l")" "$DEST$t")
  ln -sfn "$rel" "$l"
done
# BLAS/LAPACK alternatives that libopencv_core needs.
for d in blas lapack; do
  for f in "$DEST/usr/lib/$TRIPLET/$d"/lib*.so.[0-9]; do
    [ -e "$f" ] || continue
    b=$(basename "$f"); [ -e "$DEST/usr/lib/$TRIPLET/$b" ] || ln -s "$d/$b" "$DEST/usr/lib/$TRIPLET/$b"
  done
done
# glibc's libc.so / libm.so ld scripts name absolute paths: point them into DEST.
for f in $(grep -l -s 'GNU ld script' "$DEST/usr/lib/$TRIPLET"/*.so); do
  sed -i -E "s@([ (])/(usr/)?lib/@\\1$DEST/\\2lib/@g" "$f"
done
# libopencv-dev (the only package with opencv4.pc) pulls every module: write a small one.
PC="$DEST/usr/lib/$TRIPLET/pkgconfig/opencv4.pc"
[ -e "$PC" ] || cat > "$PC" <<PCEOF
prefix=/usr
libdir=\${prefix}/lib/$TRIPLET
includedir=\${prefix}/include/opencv4
Name: OpenCV
Description: OpenCV subset (core, imgproc, calib3d, aruco) from the sysroot
Version: 4.6.0
Libs: -L\${libdir} -lopencv_aruco -lopencv_calib3d -lopencv_features2d -lopencv_flann -lopencv_imgproc -lopencv_core
Cflags: -I\${includedir}
PCEOF
touch "$DEST/.frappe-count-sysroot"
du -sh "$DEST"
