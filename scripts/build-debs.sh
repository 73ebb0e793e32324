#!/usr/bin/env bash
# Builds Frappe's Debian packages with plain dpkg-deb:
#
#   libfrappe-coreS      libfrappe-core.so.S, S the soversion: major.minor until 1.0
#                        (libfrappe-core0.2), the major from then (docs/install.md)
#   libfrappe-dev        headers, .pc files, the CMake package, .so links, .gir
#   gstreamer1.0-frappe  the plugin (frappedetect, frappejson), libgstfrappemeta-1.0.so.S and
#                        its typelib GstFrappe-1.0 (Python apps)
#   frappe-tools         frappe-detect, frappe-render, vc4-dis, vc4-run, vc4-probe
#   python3-frappe       the Python package frappe for /usr/bin/python3 (the detector's
#                        extension and frappe.stream), frappe-receive, frappe-watch
#
# Each carries README.md and its man pages; libfrappe-dev the docs (docs/*.md),
# gstreamer1.0-frappe the examples, python3-frappe docs/python.md and docs/host.md,
# all in /usr/share/doc/PACKAGE.
#
# Usage: scripts/build-debs.sh [--arch amd64|arm64] [--builddir DIR [--no-rebuild]] [OUTDIR]
#
# Without --builddir it configures build-deb-ARCH (prefix /usr, libdir
# lib/<multiarch triplet>, release, no tests or examples), compiles it and
# packages its `meson install`. On an amd64 machine, arm64 is cross-built
# with scripts/arm/armv8-arm64.ini; GStreamer's and OpenCV's arm64
# development packages are not co-installable with the amd64 ones on Debian
# 12 (apt would remove libopencv-dev), so that set has no element and no
# CLI: libfrappe-coreS, libfrappe-dev and frappe-tools with the vc4 tools
# only. On an arm64 machine (a Pi) it is a native build with everything.
#
# --builddir packages an existing build instead (tests/install does so with
# the build under test). Its prefix may be other than /usr: the staged tree
# is moved to /usr, which is sound because nothing installed holds an
# absolute path (relocatable .pc files, a CMake package relative to itself,
# no rpaths). Its libdir must be lib/<triplet>.
#
# Depends: dpkg-shlibdeps (dpkg-dev) when it is there; else each ELF file's
# NEEDED libraries mapped to their packages with dpkg -S, unversioned.
# OUTDIR defaults to build-deb-ARCH/debs.
set -euo pipefail

src=$(cd "$(dirname "$0")/.." && pwd)
die() { echo "build-debs.sh: $*" >&2; exit 1; }

arch=$(dpkg --print-architecture 2>/dev/null || echo amd64)
builddir=
rebuild=1
outdir=
while [ $# -gt 0 ]; do
	case $1 in
	--arch) arch=${2:?}; shift 2 ;;
	--arch=*) arch=${1#*=}; shift ;;
	--builddir) builddir=${2:?}; shift 2 ;;
	--builddir=*) builddir=${1#*=}; shift ;;
	--no-rebuild) rebuild=0; shift ;;
	-h|--help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
	-*) die "unknown option $1" ;;
	*) outdir=$1; shift ;;
	esac
done

case $arch in
amd64) triplet=x86_64-linux-gnu ;;
arm64) triplet=aarch64-linux-gnu ;;
*) die "--arch must be amd64 or arm64, not $arch" ;;
esac
command -v dpkg-deb >/dev/null || die "dpkg-deb not found"
command -v meson >/dev/null || die "meson not found"

# ---- the build -------------------------------------------------------------

if [ -z "$builddir" ]; then
	builddir=$src/build-deb-$arch
	if [ ! -f "$builddir/meson-private/coredata.dat" ]; then
		opts=(--prefix=/usr --libdir="lib/$triplet" --buildtype=release
			-Dtests=disabled -Dexamples=disabled)
		if [ "$arch" != "$(dpkg --print-architecture 2>/dev/null || echo amd64)" ]; then
			[ "$arch" = arm64 ] || die "cross-building is set up for arm64 only"
			opts+=(--cross-file "$src/scripts/arm/armv8-arm64.ini" -Dgst=disabled -Dcli=disabled)
		fi
		meson setup "$builddir" "$src" "${opts[@]}"
	fi
	meson compile -C "$builddir"
elif [ "$rebuild" = 1 ]; then
	meson compile -C "$builddir"
fi
builddir=$(cd "$builddir" && pwd)
[ -f "$builddir/meson-private/coredata.dat" ] || die "$builddir is not a meson build directory"
[ -n "$outdir" ] || outdir=$src/build-deb-$arch/debs

# What the build is: its version and install layout.
read -r version prefix libdir relocatable < <(python3 - "$builddir/meson-info" <<'EOF'
import json, sys
info = lambda what: json.load(open(f"{sys.argv[1]}/intro-{what}.json"))
opts = {o["name"]: o["value"] for o in info("buildoptions")}
print(info("projectinfo")["version"], opts["prefix"], opts["libdir"],
      str(opts.get("pkgconfig.relocatable", False)).lower())
EOF
) || true
[ -n "$relocatable" ] || die "cannot read $builddir/meson-info"
# The soversion, as frappe-core/meson.build makes it: major.minor until 1.0.
IFS=. read -r major minor _ <<<"$version"
if [ "$major" = 0 ]; then soversion=$major.$minor; else soversion=$major; fi
corepkg=libfrappe-core$soversion
[ "$libdir" = "lib/$triplet" ] || die "$builddir has libdir $libdir: configure it with --libdir=lib/$triplet"
if [ "$prefix" != /usr ] && [ "$relocatable" != true ]; then
	die "$builddir has prefix $prefix: configure it with --prefix=/usr (or -Dpkgconfig.relocatable=true)"
fi

# ---- stage and split ---------------------------------------------------------

mkdir -p "$outdir"
outdir=$(cd "$outdir" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/frappe-debs.XXXXXX")
trap 'rm -rf "$work"' EXIT

meson install -C "$builddir" --no-rebuild --strip --quiet --destdir "$work/stage"
root=$work/stage$prefix
[ -d "$root" ] || die "nothing installed under $prefix"

lib=usr/lib/$triplet
# take PKG PATTERN...: moves the staged files matching the patterns (relative to
# the prefix, as usr/...) into package pkg's tree.
take() {
	local pkg=$1 pattern f
	shift
	for pattern in "$@"; do
		for f in "$root"/${pattern#usr/}; do
			[ -e "$f" ] || [ -L "$f" ] || continue
			local rel=usr/${f#"$root"/}
			mkdir -p "$work/pkg/$pkg/$(dirname "$rel")"
			mv "$f" "$work/pkg/$pkg/$rel"
		done
	done
}
take $corepkg "$lib/libfrappe-core.so.*"
take gstreamer1.0-frappe "$lib/gstreamer-1.0/libgstfrappe.so" "$lib/libgstfrappemeta-1.0.so.*" \
	"$lib/girepository-1.0/GstFrappe-1.0.typelib"
take libfrappe-dev usr/include/frappe usr/include/gstreamer-1.0 "$lib/libfrappe-core.so" \
	"$lib/libgstfrappemeta-1.0.so" "$lib/pkgconfig" "$lib/cmake" usr/share/gir-1.0
# The Python package, wherever meson's Python put it (lib/python3/dist-packages
# for /usr, lib/python3.X/... for another prefix), goes where Debian's python3 looks.
for pydir in "$root"/lib/python3*/*-packages/frappe; do
	[ -d "$pydir" ] || continue
	mkdir -p "$work/pkg/python3-frappe/usr/lib/python3/dist-packages"
	mv "$pydir" "$work/pkg/python3-frappe/usr/lib/python3/dist-packages/frappe"
	rmdir -p "$(dirname "$pydir")" 2>/dev/null || true
done
take python3-frappe usr/bin/frappe-receive usr/bin/frappe-watch "usr/share/man/man1/frappe-receive.1*" \
	"usr/share/man/man1/frappe-watch.1*"
# Its commands run Debian's python3, whatever Python meson ran with.
for f in "$work"/pkg/python3-frappe/usr/bin/*; do
	[ -f "$f" ] && sed -i '1s|^#!.*|#!/usr/bin/python3|' "$f"
done
take frappe-tools "usr/bin/*" "usr/share/man/man1/*"
# A file no package took is a new install() that needs a home here.
left=$(find "$root" ! -type d)
[ -z "$left" ] || die "installed but in no package: $left"
[ -d "$work/pkg/$corepkg" ] || die "no libfrappe-core.so.N installed (a static build?)"
# The build's CPU, from the library's ELF header (e_machine).
machine=$(python3 -c 'import sys; print(int.from_bytes(open(sys.argv[1], "rb").read(20)[18:20], "little"))' \
	"$(find "$work/pkg/$corepkg" -type f | head -n1)")
case $arch:$machine in
amd64:62 | arm64:183) ;;
*) die "$builddir builds for ELF machine $machine, not $arch" ;;
esac
[ -f "$work/pkg/libfrappe-dev/$lib/cmake/frappe/frappeConfig.cmake" ] ||
	die "no CMake package installed: configure $builddir with cmake installed"

# ---- control files -------------------------------------------------------------

# Our own libraries, for dpkg-shlibdeps: the packages that provide them.
mkdir -p "$work/debian"
cat >"$work/debian/shlibs.local" <<EOF
libfrappe-core $soversion $corepkg (= $version)
libgstfrappemeta-1.0 $soversion gstreamer1.0-frappe (= $version)
EOF
# dpkg-shlibdeps reads the source package's control file.
printf 'Source: frappe\n\nPackage: frappe\nArchitecture: any\n' >"$work/debian/control"

# shlibs_depends PKG: the Depends of the ELF files in PKG's tree.
shlibs_depends() {
	local dir=$work/pkg/$1 elves
	mapfile -t elves < <(find "$dir" -type f \( -name '*.so*' -o -path '*/bin/*' \) \
		-exec sh -c 'head -c4 "$1" | grep -q ELF' _ {} \; -print | sort)
	[ ${#elves[@]} -gt 0 ] || return 0
	if command -v dpkg-shlibdeps >/dev/null; then
		local out
		out=$(cd "$work" && DEB_HOST_ARCH=$arch DEB_HOST_MULTIARCH=$triplet \
			dpkg-shlibdeps -O -x"$1" -l"$work/pkg/$corepkg/$lib" \
			-l"$work/pkg/gstreamer1.0-frappe/$lib" "${elves[@]}" 2>"$work/shlibdeps.err") ||
			{ cat "$work/shlibdeps.err" >&2; return 1; }
		sed -n 's/^shlibs:Depends=//p' <<<"$out"
		return
	fi
	# No dpkg-dev: NEEDED sonames to packages, without versions.
	local so f deps=()
	for so in $(for f in "${elves[@]}"; do objdump -p "$f" | awk '$1 == "NEEDED" { print $2 }'; done | sort -u); do
		case $1:$so in
		*:libfrappe-core.so.*) deps+=("$corepkg (= $version)"); continue ;;
		gstreamer1.0-frappe:libgstfrappemeta-1.0.so.*) continue ;;
		*:libgstfrappemeta-1.0.so.*) deps+=("gstreamer1.0-frappe (= $version)"); continue ;;
		esac
		local owner
		owner=$(dpkg -S "/lib/$triplet/$so" "/usr/lib/$triplet/$so" 2>/dev/null | head -n1 | cut -d: -f1) ||
			true
		[ -n "$owner" ] || die "no package provides $so"
		deps+=("$owner")
	done
	printf '%s\n' "${deps[@]}" | sort -u | paste -sd, | sed 's/,/, /g'
}

maintainer="${DEBFULLNAME:-Frappe maintainers} <${DEBEMAIL:-frappe@localhost}>"
about=" Frappe finds square fiducial markers (ArUco and AprilTag families) in 8-bit
 camera frames, after Jones and Hauert's Frappe algorithm: fast enough for a
 Raspberry Pi's CPU, with its front end optionally on the VideoCore IV QPUs."

# control PKG SECTION MULTIARCH SUMMARY EXTRA-FIELDS...: writes PKG's DEBIAN/control.
control() {
	local pkg=$1 section=$2 multiarch=$3 summary=$4 dir=$work/pkg/$1
	shift 4
	local depends
	depends=$(shlibs_depends "$pkg") || die "cannot work out the Depends of $pkg"
	# What no ELF file says (python3-frappe's interpreter): extra_depends=... control ...
	[ -z "${extra_depends:-}" ] || depends="${depends:+$depends, }$extra_depends"
	mkdir -p "$dir/DEBIAN" "$dir/usr/share/doc/$pkg"
	# DEP-5, with the license text from LICENSE (an empty line as " .")
	{
		echo "Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/"
		echo "Upstream-Name: frappe"
		echo
		echo "Files: *"
		echo "Copyright: $(sed -n 's/^Copyright (c) //p' "$src/LICENSE")"
		echo "License: MIT"
		sed '1,/^Copyright/d' "$src/LICENSE" | sed -e '1{/^$/d}' -e 's/^$/./' -e 's/^/ /'
	} >"$dir/usr/share/doc/$pkg/copyright"
	{
		echo "Package: $pkg"
		echo "Version: $version"
		echo "Architecture: $arch"
		[ -z "$multiarch" ] || echo "Multi-Arch: $multiarch"
		echo "Maintainer: $maintainer"
		echo "Installed-Size: $(du -sk "$dir" | cut -f1)"
		[ -z "$depends" ] || echo "Depends: $depends"
		local field
		for field in "$@"; do echo "$field"; done
		echo "Section: $section"
		echo "Priority: optional"
		echo "Description: $summary"
		echo "$about"
	} >"$dir/DEBIAN/control"
}

control $corepkg libs same "Frappe fiducial marker detector - shared library"
dev_fields=("Depends: $corepkg (= $version)")
# gstfrappemeta.pc requires GStreamer's .pc files; the library itself comes
# with the element.
if [ -d "$work/pkg/gstreamer1.0-frappe" ]; then
	dev_fields+=("Recommends: gstreamer1.0-frappe (= $version), libgstreamer-plugins-base1.0-dev")
fi
control libfrappe-dev libdevel "" "Frappe fiducial marker detector - development files" "${dev_fields[@]}"
[ ! -d "$work/pkg/gstreamer1.0-frappe" ] ||
	control gstreamer1.0-frappe video same "Frappe fiducial marker detector - GStreamer elements frappedetect, frappejson"
[ ! -d "$work/pkg/frappe-tools" ] ||
	control frappe-tools video foreign "Frappe fiducial marker detector - command-line tools"
if [ -d "$work/pkg/python3-frappe" ]; then
	# The extension is built for one Python: its ABI tag (cpython-311-...) pins python3.
	py_depends=python3
	ext=$(find "$work/pkg/python3-frappe" -name '_frappe.cpython-*.so' | head -n1)
	if [ -n "$ext" ]; then
		abi=$(basename "$ext" | sed -n 's/^_frappe\.cpython-\([0-9]\)\([0-9]*\)-.*/\1.\2/p')
		py_depends="python3 (>= $abi), python3 (<< ${abi%%.*}.$((${abi#*.} + 1))), python3-numpy"
	fi
	extra_depends=$py_depends control python3-frappe python "" \
		"Frappe fiducial marker detector - Python module and host tools" \
		"Recommends: python3-gi, gir1.2-gstreamer-1.0, gstreamer1.0-frappe (= $version)"
fi

# ---- docs and examples -------------------------------------------------------

# docs PKG FILE...: copies files of the source tree into /usr/share/doc/PKG.
docs() {
	local pkg=$1 f
	shift
	[ -d "$work/pkg/$pkg" ] || return 0
	for f in "$@"; do
		mkdir -p "$work/pkg/$pkg/usr/share/doc/$pkg/$(dirname "$f")"
		cp -R "$src/$f" "$work/pkg/$pkg/usr/share/doc/$pkg/$f"
	done
}
for dir in "$work"/pkg/*; do docs "$(basename "$dir")" README.md; done
mapfile -t all_docs < <(cd "$src" && ls docs/*.md docs/*.png)
docs libfrappe-dev "${all_docs[@]}"
docs gstreamer1.0-frappe gst/README.md docs/overlay.md docs/overlay.png docs/settings.md examples
docs frappe-tools docs/settings.md docs/quality.md
docs python3-frappe docs/python.md docs/host.md examples/receive-markers.py
# Installed-Size counted before the docs: count again.
for dir in "$work"/pkg/*; do
	sed -i "s/^Installed-Size: .*/Installed-Size: $(du -sk --exclude=DEBIAN "$dir" | cut -f1)/" "$dir/DEBIAN/control"
done

# ---- the packages --------------------------------------------------------------

for dir in "$work"/pkg/*; do
	pkg=$(basename "$dir")
	find "$dir" -type d -exec chmod 0755 {} +
	deb=$outdir/${pkg}_${version}_$arch.deb
	dpkg-deb --root-owner-group --build "$dir" "$deb" >/dev/null
	echo "$deb"
done
