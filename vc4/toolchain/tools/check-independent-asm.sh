#!/bin/sh
# SPDX-License-Identifier: MIT
# Cross-check of vc4-dis against an independent assembler: every hex listing in a folder
# (e.g. GPU_FFT's hello_fft/hex/shader_*.hex) is disassembled by vc4-dis, re-assembled by
# vc4asm (maazl/vc4asm, GPLv3, built outside this project) and compared word for word.
# Not part of CI: neither vc4asm nor the shaders are in the repository.
#
#   check-independent-asm.sh VC4ASM HEX_DIR [VC4_DIS]
#
# VC4_DIS defaults to build/vc4/toolchain/vc4-dis. Exit status 0 when every file matches.
set -u

if [ $# -lt 2 ] || [ $# -gt 3 ]; then
	echo "usage: $0 VC4ASM HEX_DIR [VC4_DIS]" >&2
	exit 2
fi
vc4asm=$1
hexdir=$2
vc4dis=${3:-build/vc4/toolchain/vc4-dis}
for tool in "$vc4asm" "$vc4dis"; do
	if [ ! -x "$tool" ]; then
		echo "$0: $tool is not an executable" >&2
		exit 2
	fi
done
if [ ! -d "$hexdir" ]; then
	echo "$0: $hexdir is not a folder" >&2
	exit 2
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# One 32-bit word a line, lower case, 8 digits: the hex listing ("0xLLLLLLLL, 0xHHHHHHHH,"
# per instruction, "//" comments) and vc4asm's binary output (little endian) alike.
hexwords() {
	sed 's,//.*,,' "$1" | tr -s ', \t\r' '\n\n\n\n' | sed -n 's/^0[xX]\([0-9a-fA-F]\{1,8\}\)$/\1/p' |
		tr 'A-F' 'a-f' | awk '{ s = sprintf("%8s", $1); gsub(/ /, "0", s); print s }'
}
binwords() {
	od -An -v -tx4 "$1" | tr -s ' ' '\n' | sed '/^$/d'
}

total=0
same=0
for hex in "$hexdir"/*.hex; do
	[ -e "$hex" ] || continue
	total=$((total + 1))
	name=$(basename "$hex" .hex)
	if ! "$vc4dis" --no-comments "$hex" >"$work/$name.qasm" 2>"$work/$name.err"; then
		echo "$name: vc4-dis failed: $(cat "$work/$name.err")"
		continue
	fi
	if ! "$vc4asm" -o "$work/$name.bin" "$work/$name.qasm" >"$work/$name.err" 2>&1; then
		echo "$name: vc4asm failed:"
		sed 's/^/  /' "$work/$name.err" | head -20
		continue
	fi
	hexwords "$hex" >"$work/$name.want"
	binwords "$work/$name.bin" >"$work/$name.got"
	if cmp -s "$work/$name.want" "$work/$name.got"; then
		same=$((same + 1))
		echo "$name: same $(wc -l <"$work/$name.want") words"
	else
		echo "$name: DIFFERENT"
		# Show the first differing instruction with its listing line.
		paste -d' ' "$work/$name.want" "$work/$name.got" | awk 'NR % 2 { lo = $0; next }
			{ split(lo, a, " "); split($0, b, " ")
			  if (a[1] != a[2] || b[1] != b[2]) {
				printf "  word %d: want 0x%s, 0x%s got 0x%s, 0x%s\n", NR / 2 - 1, a[1], b[1], a[2], b[2]
				if (++n == 5) exit } }'
	fi
done
echo "$same/$total listings re-assemble to the same words"
[ "$same" -eq "$total" ] && [ "$total" -gt 0 ]
