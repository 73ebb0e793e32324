// SPDX-License-Identifier: MIT
// vc4-dis FILE: prints a vc4asm-syntax listing of a QPU program (hex listing or binary);
// words vc4asm would not re-create from an instruction's text print as ".int" data.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "isa/disasm.hpp"
#include "tools/listing.hpp"

namespace {
void usage()
{
	std::fprintf(stderr,
	             "usage: vc4-dis [--fields] [--no-comments] FILE\n"
	             "  FILE: vc4asm hex listing (0xLLLLLLLL, 0xHHHHHHHH, per line) or raw binary\n"
	             "  Words an instruction's text cannot carry print as .int data.\n"
	             "  --fields       print every instruction field after each line\n"
	             "  --no-comments  plain listing without addresses and words\n");
}
} // namespace

int main(int argc, char **argv)
{
	using namespace frappe::vc4;
	bool fields = false, comments = true;
	const char *path = nullptr;
	for (int i = 1; i < argc; ++i) {
		if (!std::strcmp(argv[i], "--fields"))
			fields = true;
		else if (!std::strcmp(argv[i], "--no-comments"))
			comments = false;
		else if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help")) {
			usage();
			return 0;
		} else if (!path)
			path = argv[i];
		else {
			usage();
			return 2;
		}
	}
	if (!path) {
		usage();
		return 2;
	}
	try {
		const auto code = tools::readCodeFile(path);
		if (!fields) {
			std::fputs(isa::disassembleProgram(code, comments).c_str(), stdout);
			return 0;
		}
		// Field dump: the listing line, then its fields as a comment.
		const std::string listing = isa::disassembleProgram(code, comments);
		size_t index = 0, pos = 0;
		while (pos < listing.size()) {
			const size_t end = listing.find('\n', pos);
			const std::string line = listing.substr(pos, end - pos);
			std::printf("%s\n", line.c_str());
			if (!line.empty() && line[0] == '\t' && index < code.size())
				std::printf("\t# %s\n", isa::fieldDump(code[index++]).c_str());
			pos = end + 1;
		}
		return 0;
	} catch (const std::exception &e) {
		std::fprintf(stderr, "vc4-dis: %s\n", e.what());
		return 1;
	}
}
