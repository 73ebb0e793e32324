#!/bin/bash
# ARMv6 (Raspberry Pi Zero, ARM1176JZF-S) or aarch64 (Pi Zero 2 W, 3, 4)
# instruction counts of frappe-core and of OpenCV 4.6's aruco module, per
# frame and per pixel, per stage.
#
# Cross-builds frappe-core for ARMv6KZ + VFPv2 (Debian's armel toolchain,
# scripts/arm/armv6-armel-sysroot.ini) or for ARMv8-A (Debian's arm64
# toolchain and multiarch libraries, scripts/arm/armv8-arm64.ini), runs
# tests/bench/frappe_count.cpp under `qemu-arm -cpu arm1176` or
# `qemu-aarch64 -cpu cortex-a53` with the instruction-counting TCG plugin
# scripts/arm/frappecount.c, and prints the tables (see docs/arm.md).
# Not a test: nothing is asserted. Needs a Debian 12 (bookworm) amd64 host.
#
# usage: scripts/arm-count.sh [options]
#   --arch A           armv6 (default) or aarch64
#   --scalar           aarch64 only: -Dsimd=disabled (the scalar kernels)
#                      instead of Highway's NEON kernels (ARMv6 is always
#                      -Dsimd=disabled, with its SIMD32 kernels)
#   --list FILE        images, one path a line (the detector contract's list format)
#   --images DIR       or every *.png / *.jpg in DIR
#                      (default: ../shared/data/synth/images beside the checkout)
#   --dictionary NAME  default aruco_mip_36h12
#   --max N            only the first N images
#   --no-opencv        count frappe only (always so with --arch aarch64)
#   --region-contrast C  Config::region_contrast for frappe (0: no region map
#                      and no region candidates; default: the Config default)
#   --mode M           normal (default), ascale or track: the list as one video in
#                      its order (ascale: what the Pi Zero model, vc4-zero-model,
#                      reads; track: Mode::Track, its whole count in the front
#                      end's column)
#   --detectors N      frame k on detector k mod N: a Pipeline of N threads'
#                      frames, each counted alone (docs/arm.md, "Four cores")
#   --bands N          the front end in N row bands on N threads, counted band
#                      by band (one at a time): the latency on N cores, in
#                      threads.md in --out (arm_threads_report.py)
#   --pipeline N       the list through a Pipeline of N threads (0: a bare
#                      Detector), each thread's count: what the pipeline adds,
#                      in threads.md in --out
#                      (--bands and --pipeline run qemu on one host core, where
#                      frappe's threads never spin: the counts stay exact)
#   --out DIR          where the results go (default: BUILD/arm-count)
#   --build DIR        cross build dir (default in the checkout: build-armel,
#                      build-arm64-count, build-arm64-count-scalar)
#   --setup            install missing host packages with apt-get (root) instead of stopping
#   --jobs N           ninja -j (default 2)
# env: FRAPPE_ARM_CACHE  where the sysroot, the plugin and the qemu header live
#                        (default ${XDG_CACHE_HOME:-$HOME/.cache}/frappe-arm)
#      SYSROOT           an existing armel sysroot to reuse (e.g. /tmp/sysroot-armel
#                        from the team's make-sysroot.sh; it needs libopencv_aruco
#                        and libpng/libjpeg headers for the OpenCV part)
# Output: the tables on stdout, and BUILD/arm-count/{report.md,count.log,...}.
set -euo pipefail

SRC=$(cd "$(dirname "$0")/.." && pwd)
HERE=$SRC/scripts/arm
LIST="" IMAGES="" DICT=aruco_mip_36h12 MAX=0 OPENCV=1 BUILD="" SETUP=0 JOBS=2 REGION="" OUT="" MODE=normal
ARCH=armv6 SCALAR=0 DETECTORS=1 BANDS=0 PIPELINE=-1
while [ $# -gt 0 ]; do
	case "$1" in
	--arch) ARCH=$2; shift 2;;
	--scalar) SCALAR=1; shift;;
	--list) LIST=$2; shift 2;;
	--images) IMAGES=$2; shift 2;;
	--dictionary) DICT=$2; shift 2;;
	--max) MAX=$2; shift 2;;
	--no-opencv) OPENCV=0; shift;;
	--region-contrast) REGION=$2; shift 2;;
	--mode) MODE=$2; shift 2;;
	--detectors) DETECTORS=$2; shift 2;;
	--bands) BANDS=$2; shift 2;;
	--pipeline) PIPELINE=$2; shift 2;;
	--out) OUT=$2; shift 2;;
	--build) BUILD=$2; shift 2;;
	--setup) SETUP=1; shift;;
	--jobs) JOBS=$2; shift 2;;
	-h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0;;
	*) echo "arm-count: unknown option $1 (see --help)" >&2; exit 2;;
	esac
done
t0=$(date +%s)
step() { echo "== [$(( $(date +%s) - t0 )) s] $*" >&2; }
die() { echo "arm-count: $1" >&2; exit "${2:-1}"; }
CACHE=${FRAPPE_ARM_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/frappe-arm}
case "$ARCH" in
armv6)
	[ "$SCALAR" = 0 ] || die "--scalar is for --arch aarch64 (the ARMv6 build has no Highway)" 2
	BUILD=${BUILD:-$SRC/build-armel}
	SYSROOT=${SYSROOT:-$CACHE/sysroot-armel}
	TRIPLET=arm-linux-gnueabi
	QEMU=(qemu-arm -cpu arm1176 -L "$SYSROOT")
	REPORT_ARCH=armv6
	;;
aarch64)
	# no sysroot: Debian's arm64 multiarch libraries (loader, libstdc++, libhwy)
	SUFFIX=""
	[ "$SCALAR" = 0 ] || SUFFIX=-scalar
	BUILD=${BUILD:-$SRC/build-arm64-count$SUFFIX}
	TRIPLET=aarch64-linux-gnu
	QEMU=(qemu-aarch64 -cpu cortex-a53 -L /)
	REPORT_ARCH=aarch64$SUFFIX
	# Debian's libopencv-dev:arm64 is not co-installable with the amd64 one
	# (it would replace hundreds of packages): frappe only
	OPENCV=0
	;;
*) die "--arch is armv6 or aarch64, not $ARCH" 2;;
esac
OUT=${OUT:-$BUILD/arm-count}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

# ---- the image list ----------------------------------------------------------
if [ -z "$LIST" ]; then
	IMAGES=${IMAGES:-$SRC/../shared/data/synth/images}
	[ -d "$IMAGES" ] || die "no --list given and no image folder $IMAGES (pass --list FILE or --images DIR)" 2
	IMAGES=$(cd "$IMAGES" && pwd)
	mkdir -p "$OUT"
	LIST=$OUT/images.txt
	find "$IMAGES" -maxdepth 1 -type f \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' \) | sort > "$LIST"
	[ -s "$LIST" ] || die "no .png/.jpg images in $IMAGES" 2
fi
[ -r "$LIST" ] || die "cannot read list $LIST" 2
LIST=$(cd "$(dirname "$LIST")" && pwd)/$(basename "$LIST")

# ---- host tools ---------------------------------------------------------------
need_pkgs=""
if [ "$ARCH" = aarch64 ]; then
	dpkg --print-foreign-architectures | grep -qx arm64 ||
		die "the arm64 architecture is not enabled: dpkg --add-architecture arm64 && apt-get update" 3
	command -v $TRIPLET-g++ >/dev/null || need_pkgs="$need_pkgs crossbuild-essential-arm64"
	# the loader and C++ runtime qemu-aarch64 -L / runs the driver with
	[ -f /usr/lib/$TRIPLET/libstdc++.so.6 ] || need_pkgs="$need_pkgs libstdc++6:arm64"
	[ "$SCALAR" = 1 ] || [ -f /usr/lib/$TRIPLET/pkgconfig/libhwy.pc ] || need_pkgs="$need_pkgs libhwy-dev:arm64"
	[ -f /usr/lib/$TRIPLET/libpng16.a ] || need_pkgs="$need_pkgs libpng-dev:arm64"
	[ -f /usr/lib/$TRIPLET/libjpeg.a ] || need_pkgs="$need_pkgs libjpeg62-turbo-dev:arm64"
	[ -f /usr/lib/$TRIPLET/libz.a ] || need_pkgs="$need_pkgs zlib1g-dev:arm64"
else
	command -v $TRIPLET-g++ >/dev/null || need_pkgs="$need_pkgs crossbuild-essential-armel"
fi
command -v "${QEMU[0]}" >/dev/null || need_pkgs="$need_pkgs qemu-user"
command -v meson >/dev/null || need_pkgs="$need_pkgs meson"
command -v ninja >/dev/null || need_pkgs="$need_pkgs ninja-build"
command -v pkg-config >/dev/null || need_pkgs="$need_pkgs pkgconf"
command -v python3 >/dev/null || need_pkgs="$need_pkgs python3"
command -v gcc >/dev/null || need_pkgs="$need_pkgs gcc"
if [ "$ARCH" = armv6 ] && [ ! -f "$SYSROOT/usr/lib/$TRIPLET/libstdc++.so.6" ] && ! command -v mmdebstrap >/dev/null; then
	need_pkgs="$need_pkgs mmdebstrap"
fi
if [ -n "$need_pkgs" ]; then
	if [ "$SETUP" = 1 ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
		step "apt-get install$need_pkgs"
		mkdir -p "$(dirname "$CACHE")" # the log sits beside the cache, which may not exist yet
		export DEBIAN_FRONTEND=noninteractive
		{ apt-get update -q && apt-get install -y -q --no-install-recommends $need_pkgs; } >"$CACHE.apt.log" 2>&1 ||
			die "apt-get install$need_pkgs failed (log: $CACHE.apt.log)" 3
	else
		die "missing host packages:$need_pkgs
  install them with: apt-get install --no-install-recommends$need_pkgs
  (Debian 12 amd64), or run this script as root with --setup" 3
	fi
fi
# qemu-user-static cannot load plugins; Debian's dynamic qemu-user can.
if ! ldd "$(command -v "${QEMU[0]}")" >/dev/null 2>&1; then
	die "$(command -v "${QEMU[0]}") is a static build, which cannot load TCG plugins: install qemu-user (not only qemu-user-static)" 3
fi

# ---- the armel sysroot -------------------------------------------------------
if [ "$ARCH" = armv6 ]; then
if [ ! -f "$SYSROOT/usr/lib/$TRIPLET/libstdc++.so.6" ]; then
	[ -e "$SYSROOT" ] && [ -n "$(ls -A "$SYSROOT" 2>/dev/null)" ] &&
		die "$SYSROOT exists but is not an armel sysroot (no usr/lib/$TRIPLET/libstdc++.so.6); remove it or set SYSROOT" 3
	step "armel sysroot -> $SYSROOT (mmdebstrap, ~1 min, ~200 MB download)"
	mkdir -p "$CACHE"
	"$HERE/make-sysroot-count.sh" "$SYSROOT" >"$CACHE/sysroot.log" 2>&1 || {
		rm -rf "$SYSROOT"
		die "making the armel sysroot failed (log: $CACHE/sysroot.log): the Debian archive must be reachable and the armel packages available" 3
	}
fi
SYSLIB=$SYSROOT/usr/lib/$TRIPLET
[ -f "$SYSROOT/usr/include/png.h" ] && [ -f "$SYSROOT/usr/include/jpeglib.h" ] ||
	die "the sysroot $SYSROOT has no libpng/libjpeg headers (install libpng-dev and libjpeg62-turbo-dev into it, or use scripts/arm/make-sysroot-count.sh)" 3
if [ "$OPENCV" = 1 ] && [ ! -e "$SYSLIB/libopencv_aruco.so" ]; then
	die "the sysroot $SYSROOT has no libopencv_aruco.so (scripts/arm/make-sysroot-count.sh adds it); or pass --no-opencv" 3
fi
else
	# the driver's image decoding: Debian's arm64 -dev packages (multiarch),
	# their archives linked statically
	SYSLIB=/usr/lib/$TRIPLET
fi

# ---- the counting plugin (needs qemu-plugin.h from Debian's qemu source) ------
PLUGIN=$CACHE/plugin/libfrappecount.so
QSRC=$CACHE/qemu-src
if [ ! -f "$QSRC/include/qemu-plugin.h" ]; then
	step "qemu-plugin.h from Debian's qemu source package"
	mkdir -p "$QSRC/lists/partial" "$QSRC/cache/archives/partial" "$QSRC/include"
	uris=$( { grep -h '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}';
		  grep -h '^deb ' /etc/apt/sources.list 2>/dev/null | awk '{print $2}'; } | sort -u || true)
	MAIN=$(echo "$uris" | grep -v security | head -1 || true); SEC=$(echo "$uris" | grep security | head -1 || true)
	MAIN=${MAIN:-http://deb.debian.org/debian}
	{ echo "deb-src $MAIN bookworm main"; echo "deb-src $MAIN bookworm-updates main"
	  [ -n "$SEC" ] && echo "deb-src $SEC bookworm-security main"; } > "$QSRC/sources.list"
	APTO=(-o Dir::Etc::SourceList="$QSRC/sources.list" -o Dir::Etc::SourceParts=/nonexistent
	      -o Dir::State::Lists="$QSRC/lists" -o Dir::Cache="$QSRC/cache" -o APT::Sandbox::User=root)
	VER=$(dpkg-query -W -f='${source:Version}' qemu-user 2>/dev/null || true)
	( cd "$QSRC" && apt-get "${APTO[@]}" update -qq &&
	  { [ -n "$VER" ] && apt-get "${APTO[@]}" source -d -qq "qemu=$VER" || apt-get "${APTO[@]}" source -d -qq qemu; } &&
	  tar -xJf "$(ls qemu_*.orig.tar.* | head -1)" --wildcards '*/include/qemu/qemu-plugin.h' &&
	  cp qemu-*/include/qemu/qemu-plugin.h include/ && rm -rf qemu_*.orig.tar.* qemu_*.debian.tar.* qemu-*/ ) \
		>"$CACHE/qemu-src.log" 2>&1 || die "could not get qemu-plugin.h (log: $CACHE/qemu-src.log)" 3
fi
if [ ! -f "$PLUGIN" ] || [ "$HERE/frappecount.c" -nt "$PLUGIN" ]; then
	step "plugin $PLUGIN"
	mkdir -p "$(dirname "$PLUGIN")"
	gcc -O2 -Wall -Wextra -Wno-unused-parameter -shared -fPIC -I"$QSRC/include" \
		"$HERE/frappecount.c" -o "$PLUGIN"
fi

# ---- cross build of frappe-core (static; ARMv6: no Highway, its row kernels) --
mkdir -p "$CACHE"
if [ "$ARCH" = armv6 ]; then
	XF=$CACHE/sysroot-armel.ini
	printf "[constants]\nsysroot = '%s'\n" "$SYSROOT" > "$XF.tmp"
	cmp -s "$XF.tmp" "$XF" 2>/dev/null && rm "$XF.tmp" || mv "$XF.tmp" "$XF"
	XFILES=(--cross-file "$XF" --cross-file "$HERE/armv6-armel-sysroot.ini")
	WHAT="ARMv6KZ + VFPv2" SIMD=disabled
else
	XFILES=(--cross-file "$HERE/armv8-arm64.ini")
	WHAT="ARMv8-A, $([ "$SCALAR" = 1 ] && echo scalar || echo "Highway NEON")"
	SIMD=$([ "$SCALAR" = 1 ] && echo disabled || echo enabled)
fi
if [ ! -f "$BUILD/build.ninja" ]; then
	step "meson setup $BUILD (cross, $WHAT)"
	opts=(--buildtype=release -Ddefault_library=static "-Dsimd=$SIMD")
	# switch off whatever the project can build beside the library
	for o in gst vc4 tests examples cli; do
		grep -q "option('$o'" "$SRC/meson_options.txt" && opts+=("-D$o=disabled")
	done
	meson setup "$BUILD" "$SRC" "${XFILES[@]}" "${opts[@]}" \
		>"$CACHE/meson-setup.log" 2>&1 || { cat "$CACHE/meson-setup.log" >&2; die "meson setup failed" 4; }
elif ! python3 -c "import json,sys; sys.exit(0 if any(o['name'] == 'simd' and o['value'] == '$SIMD'
		for o in json.load(open('$BUILD/meson-info/intro-buildoptions.json'))) else 1)" 2>/dev/null; then
	die "$BUILD was not set up with -Dsimd=$SIMD (a build of another --arch or --scalar?): pass another --build" 4
fi
step "ninja: frappe-core ($WHAT)"
LIB=frappe-core/libfrappe-core.a
ninja -C "$BUILD" -j"$JOBS" "$LIB" >&2 || die "cross build of frappe-core failed" 4

step "driver tests/bench/frappe_count.cpp"
mkdir -p "$OUT"
CXXFLAGS=(-std=c++20 -O3 -pthread -I"$SRC/frappe-core/include" -I"$BUILD/frappe-core/include")
# frappe-core/src's rooms (front_end, trace, read, ...): headers by file name
for room in "$SRC"/frappe-core/src/*/; do CXXFLAGS+=(-I"$room"); done
LIBS=("$BUILD/$LIB")
if [ "$ARCH" = armv6 ]; then
	CXXFLAGS+=(-march=armv6kz -mtune=arm1176jzf-s -mfpu=vfp -mfloat-abi=softfp
		   -isystem "$SYSROOT/usr/include" -isystem "$SYSROOT/usr/include/$TRIPLET")
	if [ "$OPENCV" = 1 ]; then
		CXXFLAGS+=(-DFRAPPE_COUNT_OPENCV -isystem "$SYSROOT/usr/include/opencv4")
		LIBS+=(-lopencv_aruco -lopencv_calib3d -lopencv_imgproc -lopencv_core)
	fi
	LIBS+=(-L"$SYSLIB" -lpng16 -ljpeg -lz -Wl,-rpath-link,"$SYSLIB" -Wl,-rpath-link,"$SYSROOT/lib/$TRIPLET")
else
	# the archives by path: -L/usr/lib/$TRIPLET could also put the multiarch
	# libc before the cross toolchain's; their headers are the host's
	# (/usr/include, and jconfig.h in /usr/include/$TRIPLET)
	CXXFLAGS+=(-idirafter /usr/include -idirafter "/usr/include/$TRIPLET")
	[ "$SCALAR" = 1 ] || LIBS+=(/usr/lib/$TRIPLET/libhwy.so)
	LIBS+=("$SYSLIB/libpng16.a" "$SYSLIB/libjpeg.a" "$SYSLIB/libz.a" -lm)
fi
# -no-pie: the plugin's addresses then match the executable's symbol table.
$TRIPLET-g++ "${CXXFLAGS[@]}" -no-pie -o "$OUT/frappe-count" "$SRC/tests/bench/frappe_count.cpp" \
	"${LIBS[@]}" -Wl,-Map,"$OUT/frappe-count.map" || die "building the driver failed" 4
$TRIPLET-nm -n -S -C "$OUT/frappe-count" > "$OUT/frappe-count.syms"
# The markers' entry addresses, where the plugin fires them (and nowhere
# else in them). One straddling a 4 KiB page (the driver aligns them so none
# does) would be split in two translation blocks: say so, as a layout change.
# (functions only, not their `sink` variables; OpenCV's only when it runs)
awk -v cv="$OPENCV" '$3 ~ /^[Tt]$/ && $4 ~ /^armcount_mark_[a-z_]*$/ && (cv == 1 || $4 !~ /opencv/) { print $1, $4 }' \
	"$OUT/frappe-count.syms" > "$OUT/marks.txt"
[ -s "$OUT/marks.txt" ] || die "no armcount_mark_* symbols in $OUT/frappe-count" 4
awk '$3 ~ /^[Tt]$/ && $4 ~ /^armcount_mark_[a-z_]*$/ { print $1, $2, $4 }' "$OUT/frappe-count.syms" | while read -r a z name; do
	[ $(( 16#$a >> 12 )) = $(( (16#$a + 16#$z - 1) >> 12 )) ] || echo "arm-count: note: $name straddles a 4 KiB page" >&2
done

# ---- count -------------------------------------------------------------------
n=$(grep -cv '^\s*\(#\|$\)' "$LIST" || true)
[ "$MAX" -gt 0 ] && [ "$MAX" -lt "$n" ] && n=$MAX
step "counting $n images under ${QEMU[*]:0:3} (OpenCV: $([ "$OPENCV" = 1 ] && echo yes || echo no))"
args=(--list "$LIST" --dictionary "$DICT" --max "$MAX" --out-frappe "$OUT/frappe.jsonl")
[ "$OPENCV" = 1 ] && args+=(--out-opencv "$OUT/opencv.jsonl") || args+=(--no-opencv)
[ -n "$REGION" ] && args+=(--region-contrast "$REGION")
args+=(--mode "$MODE")
PLUGARGS="$PLUGIN,out=$OUT/count.log,marks=$OUT/marks.txt" PIN=()
[ "$DETECTORS" -gt 1 ] && args+=(--detectors "$DETECTORS")
[ "$BANDS" -gt 0 ] && args+=(--bands "$BANDS")
[ "$PIPELINE" -ge 0 ] && args+=(--pipeline "$PIPELINE") && PLUGARGS="$PLUGARGS,vcpus=1"
# one host core: std::thread::hardware_concurrency() is then 1 in the guest,
# and frappe's workers sleep instead of polling (src/base/worker.cpp)
[ "$BANDS" -gt 0 ] || [ "$PIPELINE" -ge 0 ] && PIN=(taskset -c 0)
# relative paths in the list are relative to the current directory (the contract)
( "${PIN[@]}" "${QEMU[@]}" -d plugin -plugin "$PLUGARGS" \
	"$OUT/frappe-count" "${args[@]}" > "$OUT/driver.txt" 2> "$OUT/qemu.log" ) ||
	{ tail -20 "$OUT/qemu.log" >&2; die "the counting run failed (log: $OUT/qemu.log)" 5; }

if [ "$BANDS" -gt 0 ] || [ "$PIPELINE" -ge 0 ]; then
	step "report (threads)"
	python3 "$HERE/arm_threads_report.py" --log "$OUT/count.log" --map "$OUT/frappe-count.map" \
		--syms "$OUT/frappe-count.syms" --driver "$OUT/driver.txt" --md "$OUT/threads.md" \
		--csv "$OUT/threads.csv"
	step "done: $OUT/threads.md"
	exit 0
fi
step "report"
python3 "$HERE/arm_count_report.py" --log "$OUT/count.log" --map "$OUT/frappe-count.map" \
	--syms "$OUT/frappe-count.syms" --driver "$OUT/driver.txt" --md "$OUT/report.md" \
	--csv "$OUT/frames.csv" --arch "$REPORT_ARCH"
step "done: $OUT/report.md"
