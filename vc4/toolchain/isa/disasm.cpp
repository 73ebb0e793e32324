// SPDX-License-Identifier: MIT
#include "disasm.hpp"

#include <array>
#include <cinttypes>
#include <cstdio>
#include <map>
#include <sstream>

namespace frappe::vc4::isa {

namespace {

template<typename... Args>
std::string format(const char *fmt, Args... args)
{
	char buf[160];
	std::snprintf(buf, sizeof(buf), fmt, args...);
	return buf;
}

// Special read registers 32..63, columns A and B (reference guide Table 14, vc4asm names).
// Empty entries have no name and print as ra<N>/rb<N>.
constexpr std::array<std::array<const char *, 2>, 32> kReadSpecial = {{
	{"unif", "unif"}, {nullptr, nullptr}, {nullptr, nullptr}, {"vary", "vary"},
	{nullptr, nullptr}, {nullptr, nullptr}, {"elem_num", "qpu_num"}, {"nop", "nop"},
	{nullptr, nullptr}, {"x_coord", "y_coord"}, {"ms_mask", "rev_flag"}, {nullptr, nullptr},
	{nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr},
	{"vpm", "vpm"}, {"vr_busy", "vw_busy"}, {"vr_wait", "vw_wait"}, {"mutex", "mutex"},
	{nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr},
	{nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr},
	{nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr}, {nullptr, nullptr},
}};

constexpr std::array<std::array<const char *, 2>, 32> kWriteSpecial = {{
	{"r0", "r0"}, {"r1", "r1"}, {"r2", "r2"}, {"r3", "r3"},
	{"tmurs", "tmurs"}, {"r5quad", "r5rep"}, {"irq", "irq"}, {"-", "-"},
	{"unif_addr", "unif_addr_rel"}, {"x_coord", "y_coord"}, {"ms_mask", "rev_flag"},
	{"stencil", "stencil"}, {"tlbz", "tlbz"}, {"tlbm", "tlbm"}, {"tlbc", "tlbc"},
	{"tlbam", "tlbam"}, {"vpm", "vpm"}, {"vr_setup", "vw_setup"}, {"vr_addr", "vw_addr"},
	{"mutex", "mutex"}, {"recip", "recip"}, {"recipsqrt", "recipsqrt"}, {"exp", "exp"},
	{"log", "log"}, {"t0s", "t0s"}, {"t0t", "t0t"}, {"t0r", "t0r"}, {"t0b", "t0b"},
	{"t1s", "t1s"}, {"t1t", "t1t"}, {"t1r", "t1r"}, {"t1b", "t1b"},
}};

constexpr std::array<const char *, 32> kAddOps = {
	"nop", "fadd", "fsub", "fmin", "fmax", "fminabs", "fmaxabs", "ftoi",
	"itof", "addop9?", "addop10?", "addop11?", "add", "sub", "shr", "asr",
	"ror", "shl", "min", "max", "and", "or", "xor", "not",
	"clz", "addop25?", "addop26?", "addop27?", "addop28?", "addop29?", "av8adds", "av8subs",
};
// vc4asm names the ADD ALU's v8adds/v8subs "av8adds"/"av8subs"; plain names are MUL ops.
constexpr std::array<const char *, 8> kMulOps = {
	"nop", "fmul", "mul24", "v8muld", "v8min", "v8max", "v8adds", "v8subs",
};
constexpr std::array<const char *, 14> kSignals = {
	"; bkpt", "", "; thrsw", "; thrend", "; sbwait", "; sbdone", "; lthrsw", "; loadcv",
	"; loadc", "; ldcend", "; ldtmu0", "; ldtmu1", "; loadam", "",
};
constexpr std::array<const char *, 8> kConds = {
	".never", "", ".ifz", ".ifnz", ".ifn", ".ifnn", ".ifc", ".ifcc",
};
constexpr std::array<const char *, 16> kBranchConds = {
	".allz", ".allnz", ".anyz", ".anynz", ".alln", ".allnn", ".anyn", ".anynn",
	".allc", ".allnc", ".anyc", ".anync", ".cc12?", ".cc13?", ".cc14?", "",
};
constexpr std::array<const char *, 16> kPackA = {
	"", ".16a", ".16b", ".8abcd", ".8a", ".8b", ".8c", ".8d",
	".32s", ".16as", ".16bs", ".8abcds", ".8as", ".8bs", ".8cs", ".8ds",
};
constexpr std::array<const char *, 16> kPackMul = {
	"", ".pm01?", ".pm02?", ".8abcd", ".8a", ".8b", ".8c", ".8d",
	".pm08?", ".pm09?", ".pm10?", ".pm11?", ".pm12?", ".pm13?", ".pm14?", ".pm15?",
};
constexpr std::array<const char *, 8> kUnpack = {
	"", ".16a", ".16b", ".8dr", ".8a", ".8b", ".8c", ".8d",
};
constexpr std::array<const char *, 48> kSmallImm = {
	"0", "1", "2", "3", "4", "5", "6", "7", "8", "9", "10", "11", "12", "13", "14", "15",
	"-16", "-15", "-14", "-13", "-12", "-11", "-10", "-9",
	"-8", "-7", "-6", "-5", "-4", "-3", "-2", "-1",
	"1.0", "2.0", "4.0", "8.0", "16.0", "32.0", "64.0", "128.0",
	"1./256", "1./128", "1./64", "1./32", "1./16", "1./8", "1./4", "1./2",
};

bool readNameIsShared(uint8_t raddr)
{
	if (raddr < 32)
		return false;
	const auto &names = kReadSpecial[raddr - 32];
	return names[0] && names[1] && std::string(names[0]) == names[1];
}

bool writeNameIsShared(uint8_t waddr)
{
	if (waddr < 32)
		return false;
	const auto &names = kWriteSpecial[waddr - 32];
	return std::string(names[0]) == names[1];
}

// A read name that pins the register file: vc4asm picks the file freely for shared
// names such as "unif", which would change raddr_a/raddr_b on re-assembly.
std::string pinnedReadName(uint8_t raddr, bool fileB)
{
	if (readNameIsShared(raddr))
		return format("r%c%u", fileB ? 'b' : 'a', raddr);
	return readRegisterName(raddr, fileB);
}

std::string smallImmediateText(uint8_t code)
{
	return code < 48 ? kSmallImm[code] : format("%d", static_cast<int>(code) - 64);
}

std::string sourceName(const Alu &i, Mux mux)
{
	std::string s;
	switch (mux) {
	case Mux::A:
		s = pinnedReadName(i.raddr_a, false);
		break;
	case Mux::B:
		s = i.sig == Sig::SmallImmediate ? smallImmediateText(i.raddr_b)
		                                 : pinnedReadName(i.raddr_b, true);
		break;
	default:
		s = format("r%u", static_cast<unsigned>(mux));
	}
	if ((!i.pm && mux == Mux::A) || (i.pm && mux == Mux::R4))
		s += kUnpack[static_cast<unsigned>(i.unpack)];
	return s;
}

// Destination names of the ADD and MUL writes. vc4asm takes ws from the first name that
// belongs to one file only; when every printed name is shared (r0, tmu0_s, "-") and
// ws = 1, the first printed one is pinned (rb32, ra39) so that vc4asm sets ws again.
std::array<std::string, 2> destNames(bool ws, uint8_t waddr_add, uint8_t waddr_mul,
                                     bool add_printed, bool mul_printed)
{
	std::string add = writeRegisterName(waddr_add, ws);
	std::string mul = writeRegisterName(waddr_mul, !ws);
	const bool add_decides = add_printed && !writeNameIsShared(waddr_add);
	const bool mul_decides = mul_printed && !writeNameIsShared(waddr_mul);
	if (ws && !add_decides && !mul_decides) {
		if (add_printed)
			add = format("rb%u", waddr_add);
		else if (mul_printed)
			mul = format("ra%u", waddr_mul);
	}
	return {add, mul};
}

// Which ALU inputs a used op reads (a unary ADD op reads add_a only).
bool addReads(const Alu &i, Mux m)
{
	return i.op_add != AddOp::Nop && (i.add_a == m || (!isUnary(i.op_add) && i.add_b == m));
}

bool mulReads(const Alu &i, Mux m)
{
	return i.op_mul != MulOp::Nop && (i.mul_a == m || i.mul_b == m);
}

bool reads(const Alu &i, Mux m) { return addReads(i, m) || mulReads(i, m); }

// vc4asm writes cond = never for a destination "-" (AssembleInst::optimize) and can only
// set ws through a printed destination.
bool writesExpressible(const Writes &w, bool add_printed, bool mul_printed)
{
	if (w.waddr_add == waddr::nop && w.cond_add != Cond::Never && !w.sf)
		return false;
	if (w.waddr_mul == waddr::nop && w.cond_mul != Cond::Never &&
	    (!w.sf || add_printed || !mul_printed))
		return false;
	return !w.ws || add_printed || mul_printed;
}

bool packExpressible(const Alu &i, bool add, bool mul)
{
	const auto pack = static_cast<unsigned>(i.pack);
	if (i.pack != Pack::None) {
		// Regfile A pack on an ADD write to file A (the saturating 8-bit modes are
		// also MUL packs, vc4asm could move them), or a MUL 8-bit colour pack (only
		// 3 bits of the field survive vc4asm's encoder when pm = 1).
		const bool ok = i.pm ? mul && pack >= 3 && pack <= 7 && !(i.ws && i.waddr_mul < 32)
		                     : add && !i.ws && i.waddr_add < 32 && pack <= 10;
		if (!ok)
			return false;
	}
	if (i.unpack != Unpack::None) {
		// One ALU, reading the unpacked input (regfile A below 32, or r4 when pm = 1):
		// vc4asm refuses an unpack that also changes the other ALU's operands.
		if (add == mul || (!i.pm && i.raddr_a >= 32))
			return false;
		return reads(i, i.pm ? Mux::R4 : Mux::A);
	}
	return i.pack != Pack::None || !i.pm;
}

bool smallImmediateExpressible(const Alu &i, bool add, bool mul)
{
	if (i.raddr_b >= 48) {
		// MUL rotation ".rot n," (n = 1..15); by r5 vc4asm's syntax differs between versions.
		return mul && i.raddr_b != smallimm::rotate_by_r5 && !reads(i, Mux::B);
	}
	if (add && !isUnary(i.op_add) && i.add_b == Mux::B) {
		// vc4asm rewrites "add x, 0, 0" into sub, and reads a shift's count as 5 bits.
		if ((i.op_add == AddOp::Add || i.op_add == AddOp::Sub) && i.add_a == Mux::B && i.raddr_b == 0)
			return false;
		const bool shift = i.op_add == AddOp::Shr || i.op_add == AddOp::Asr ||
		                   i.op_add == AddOp::Ror || i.op_add == AddOp::Shl;
		if (shift && i.raddr_b >= 32)
			return false;
	}
	// vc4asm turns a constant computed from the small immediate alone into ldi.
	const bool whole_word = ((1u << static_cast<unsigned>(i.pack)) & 0x0909u) != 0;
	if (whole_word && i.raddr_a == raddr::nop && !i.sf) {
		if (!mul && i.add_a == Mux::B && i.add_b == Mux::B)
			return false;
		if (!add && i.mul_a == Mux::B && i.mul_b == Mux::B)
			return false;
	}
	return true;
}

bool printable(const Alu &i)
{
	const bool add = i.op_add != AddOp::Nop, mul = i.op_mul != MulOp::Nop;
	if (add && !isValid(i.op_add))
		return false;
	// The breakpoint signal is spelt "bkpt" by the current vc4asm but "bpkt"/"break" by
	// older ones, and no shader's code holds one: in GPU_FFT it is only the data table at
	// the start of shader_256_new (words of 0x0000xxxx / 0x8802xxxx), so it stays data.
	if (i.sig == Sig::Breakpoint)
		return false;
	// An idle ALU keeps vc4asm's defaults: no destination, inputs r0, cond never.
	if (!add && (i.waddr_add != waddr::nop || i.add_a != Mux::R0 || i.add_b != Mux::R0 ||
	             i.cond_add != Cond::Never || i.sf))
		return false;
	if (!mul && (i.waddr_mul != waddr::nop || i.mul_a != Mux::R0 || i.mul_b != Mux::R0))
		return false;
	if (add && isUnary(i.op_add) && i.add_b != Mux::R0)
		return false;
	if (!writesExpressible(i, add, mul) || !packExpressible(i, add, mul))
		return false;
	if (i.sig == Sig::SmallImmediate)
		return smallImmediateExpressible(i, add, mul);
	// vc4asm turns "sub/xor x, a, a" and "v8subs x, a, a" alone into "ldi x, 0".
	if (i.sig == Sig::None && i.raddr_a == raddr::nop && i.raddr_b == raddr::nop) {
		if (add && (i.op_add == AddOp::Sub || i.op_add == AddOp::Xor) && i.add_a == i.add_b &&
		    i.waddr_mul == waddr::nop)
			return false;
		if (mul && i.op_mul == MulOp::V8Subs && i.mul_a == i.mul_b && !i.sf &&
		    i.waddr_add == waddr::nop)
			return false;
	}
	return true;
}

bool loadWritesExpressible(const Writes &w)
{
	const bool add = w.waddr_add != waddr::nop, mul = w.waddr_mul != waddr::nop;
	if (w.pm || w.pack != Pack::None || (w.sf && !add))
		return false;
	return writesExpressible(w, add, mul) && (add || w.cond_add == Cond::Never);
}

bool printable(const LoadImm &i)
{
	const auto mode = static_cast<LoadMode>(i.mode);
	return (mode == LoadMode::Word || mode == LoadMode::PerElementSigned ||
	        mode == LoadMode::PerElementUnsigned) &&
	       loadWritesExpressible(i);
}

bool printable(const Semaphore &i) { return loadWritesExpressible(i); }

bool printable(const Branch &i)
{
	const auto cond = static_cast<unsigned>(i.cond);
	if (i.ignored || (cond > 11 && i.cond != BranchCond::Always))
		return false;
	// vc4asm writes raddr_a = 0 without a register; an odd register reads as ".setf".
	if (i.reg ? (i.raddr_a & 1) : i.raddr_a != 0)
		return false;
	return !i.ws || i.waddr_add != waddr::nop || i.waddr_mul != waddr::nop;
}

std::string aluText(const Alu &i)
{
	const bool add = i.op_add != AddOp::Nop, mul = i.op_mul != MulOp::Nop;
	const auto dst = destNames(i.ws, i.waddr_add, i.waddr_mul, add, mul);
	std::string out;
	if (!add) {
		out = "nop";
	} else {
		out = kAddOps[static_cast<unsigned>(i.op_add)];
		out += kConds[static_cast<unsigned>(i.cond_add)];
		if (i.sf)
			out += ".setf";
		out += ' '; out += dst[0];
		if (!i.pm && !i.ws)
			out += kPackA[static_cast<unsigned>(i.pack)];
		out += ", " + sourceName(i, i.add_a);
		if (!isUnary(i.op_add))
			out += ", " + sourceName(i, i.add_b);
	}
	if (mul) {
		out += "; ";
		out += kMulOps[static_cast<unsigned>(i.op_mul)];
		out += kConds[static_cast<unsigned>(i.cond_mul)];
		if (i.sf && !add)
			out += ".setf";
		if (i.sig == Sig::SmallImmediate && smallimm::isRotation(i.raddr_b)) {
			if (i.raddr_b == smallimm::rotate_by_r5)
				out += ".rot r5,";
			else
				out += format(".rot %d,", i.raddr_b - 48);
		}
		out += ' '; out += dst[1];
		if (i.pm)
			out += kPackMul[static_cast<unsigned>(i.pack)];
		else if (i.ws)
			out += kPackA[static_cast<unsigned>(i.pack)];
		out += ", " + sourceName(i, i.mul_a) + ", " + sourceName(i, i.mul_b);
	}
	// A register read no input uses still happens (vw_wait stalls, unif pops a uniform):
	// "read" keeps raddr_a/raddr_b.
	if (i.raddr_a != raddr::nop && !reads(i, Mux::A))
		out += "; read " + sourceName(i, Mux::A);
	const bool b_read = i.sig == Sig::SmallImmediate ? i.raddr_b < 48 : i.raddr_b != raddr::nop;
	if (b_read && !reads(i, Mux::B))
		out += "; read " + sourceName(i, Mux::B);
	out += kSignals[static_cast<unsigned>(i.sig) < kSignals.size() ? static_cast<unsigned>(i.sig) : 1];
	return out;
}

std::string immediateText(uint32_t v)
{
	const auto s = static_cast<int32_t>(v);
	if (s > -256 && s < 256)
		return format("%d", s);
	return format("0x%x", v);
}

std::string perElementText(uint32_t v, bool is_signed)
{
	std::string out = "[";
	for (unsigned e = 0; e < 16; ++e) {
		int x = static_cast<int>(((v >> (16 + e)) & 1) << 1 | ((v >> e) & 1));
		if (is_signed && x >= 2)
			x -= 4;
		out += format("%d", x);
		out += e == 15 ? "]" : ",";
	}
	return out;
}

// Destinations of ldi/semaphore/branch, each with pack and condition when asked: "-"
// for none, "-, M" when only the MUL write is present (the first name is the ADD's).
std::string writeList(const Writes &w, bool with_pack_cond)
{
	const bool add = w.waddr_add != waddr::nop, mul = w.waddr_mul != waddr::nop;
	const auto dst = destNames(w.ws, w.waddr_add, w.waddr_mul, add, mul);
	std::string out = add ? dst[0] : "-";
	if (add && with_pack_cond) {
		if (!w.pm)
			out += kPackA[static_cast<unsigned>(w.pack)];
		out += kConds[static_cast<unsigned>(w.cond_add)];
	}
	if (mul) {
		out += ", " + dst[1];
		if (with_pack_cond) {
			if (w.pm)
				out += kPackMul[static_cast<unsigned>(w.pack)];
			out += kConds[static_cast<unsigned>(w.cond_mul)];
		}
	}
	return out + ", ";
}

std::string loadText(const LoadImm &i)
{
	static constexpr std::array<const char *, 8> names = {
		"ldi", "ldipes", "ldi02?", "ldipeu", "s", "ldi05?", "ldi06?", "ldi07?",
	};
	std::string out = names[i.mode & 7];
	if (i.sf)
		out += ".setf";
	out += ' '; out += writeList(i, true);
	if (i.mode == static_cast<uint8_t>(LoadMode::PerElementSigned))
		out += perElementText(i.value, true);
	else if (i.mode == static_cast<uint8_t>(LoadMode::PerElementUnsigned))
		out += perElementText(i.value, false);
	else
		out += immediateText(i.value);
	return out;
}

std::string semaphoreText(const Semaphore &i)
{
	std::string out = i.down ? "sacq" : "srel";
	if (i.sf)
		out += ".setf";
	out += ' '; out += writeList(i, true);
	out += immediateText(i.number | (i.ignored << 5));
	return out;
}

// "brr[.cond] dest, target", "brr dest, ra<N>[, target]"; with a MUL link register vc4asm
// reads two destinations, then a register or "-", then the target.
std::string branchText(const Branch &i, const std::string &label)
{
	std::string out = i.rel ? "brr" : "bra";
	out += kBranchConds[static_cast<unsigned>(i.cond)];
	Writes w;
	w.ws = i.ws;
	w.waddr_add = i.waddr_add;
	w.waddr_mul = i.waddr_mul;
	out += ' '; out += writeList(w, false);
	const std::string target = !label.empty() ? label
	                           : i.rel       ? format("%+d", i.offset)
	                                         : format("0x%x", static_cast<uint32_t>(i.offset));
	const bool two_dests = i.waddr_mul != waddr::nop;
	if (two_dests)
		return out + (i.reg ? readRegisterName(i.raddr_a, false) : "-") + ", " + target;
	if (!i.reg)
		return out + target;
	out += readRegisterName(i.raddr_a, false);
	if (i.offset != 0 || !label.empty())
		out += ", " + target;
	return out;
}

std::string instructionText(const Instr &instr, const std::string &label)
{
	if (const auto *a = std::get_if<Alu>(&instr))
		return aluText(*a);
	if (const auto *l = std::get_if<LoadImm>(&instr))
		return loadText(*l);
	if (const auto *s = std::get_if<Semaphore>(&instr))
		return semaphoreText(*s);
	return branchText(std::get<Branch>(instr), label);
}

// Two 32-bit data words, low first: ".int" is 32 bits in every vc4asm version, while
// ".long" became 64 bits (directive table of Parser.tables.cpp).
std::string dataText(uint64_t word)
{
	return format(".int 0x%08x, 0x%08x", static_cast<uint32_t>(word),
	              static_cast<uint32_t>(word >> 32));
}

} // namespace

std::string readRegisterName(uint8_t raddr, bool fileB)
{
	raddr &= 63;
	if (raddr < 32)
		return format("r%c%u", fileB ? 'b' : 'a', raddr);
	const char *name = kReadSpecial[raddr - 32][fileB];
	return name ? name : format("r%c%u", fileB ? 'b' : 'a', raddr);
}

std::string writeRegisterName(uint8_t waddr, bool fileB)
{
	waddr &= 63;
	if (waddr < 32)
		return format("r%c%u", fileB ? 'b' : 'a', waddr);
	return kWriteSpecial[waddr - 32][fileB];
}

bool printsAsInstruction(uint64_t word)
{
	return std::visit([](const auto &i) { return printable(i); }, decode(word));
}

std::string disassemble(uint64_t word)
{
	if (!printsAsInstruction(word))
		return dataText(word);
	return instructionText(decode(word), {});
}

std::string disassembleProgram(std::span<const uint64_t> words, bool with_comments)
{
	// Relative targets count from the fourth instruction after the branch (section 3
	// "Branches": PC + 4 instructions). Only printed branches get labels.
	std::map<uint32_t, std::string> labels;
	const auto size = static_cast<uint32_t>(words.size() * 8);
	for (size_t n = 0; n < words.size(); ++n) {
		const Instr instr = decode(words[n]);
		const auto *b = std::get_if<Branch>(&instr);
		if (!b || !b->rel || b->reg || !printable(*b))
			continue;
		const int64_t target = static_cast<int64_t>(n * 8 + 32) + b->offset;
		if (target >= 0 && target <= size && target % 8 == 0)
			labels.emplace(static_cast<uint32_t>(target), format("L%x", static_cast<unsigned>(target)));
	}
	std::ostringstream out;
	for (size_t n = 0; n < words.size(); ++n) {
		const auto address = static_cast<uint32_t>(n * 8);
		if (auto it = labels.find(address); it != labels.end())
			out << ':' << it->second << '\n';
		const Instr instr = decode(words[n]);
		std::string label;
		if (const auto *b = std::get_if<Branch>(&instr); b && b->rel && !b->reg) {
			const int64_t target = static_cast<int64_t>(address) + 32 + b->offset;
			auto it = target >= 0 ? labels.find(static_cast<uint32_t>(target)) : labels.end();
			if (it != labels.end())
				label = "r:" + it->second;
		}
		const bool as_instruction = printsAsInstruction(words[n]);
		const std::string text = as_instruction ? instructionText(instr, label) : dataText(words[n]);
		if (!with_comments) {
			out << '\t' << text << '\n';
			continue;
		}
		out << '\t' << format("%-56s", text.c_str())
		    << format(" # %04x: %016" PRIx64, address, words[n]);
		if (!as_instruction)
			out << " (" << instructionText(instr, label) << ")";
		out << '\n';
	}
	if (auto it = labels.find(size); it != labels.end())
		out << ':' << it->second << '\n';
	return out.str();
}

std::string fieldDump(uint64_t word)
{
	const Instr instr = decode(word);
	auto writes = [](const Writes &w) {
		return format("pm=%u pack=%u cond_add=%u cond_mul=%u sf=%u ws=%u waddr_add=%u waddr_mul=%u",
		              w.pm, static_cast<unsigned>(w.pack), static_cast<unsigned>(w.cond_add),
		              static_cast<unsigned>(w.cond_mul), w.sf, w.ws, w.waddr_add, w.waddr_mul);
	};
	if (const auto *a = std::get_if<Alu>(&instr))
		return format("sig=%u unpack=%u ", static_cast<unsigned>(a->sig),
		              static_cast<unsigned>(a->unpack)) +
		       writes(*a) +
		       format(" op_mul=%u op_add=%u raddr_a=%u raddr_b=%u add_a=%u add_b=%u mul_a=%u mul_b=%u",
		              static_cast<unsigned>(a->op_mul), static_cast<unsigned>(a->op_add),
		              a->raddr_a, a->raddr_b, static_cast<unsigned>(a->add_a),
		              static_cast<unsigned>(a->add_b), static_cast<unsigned>(a->mul_a),
		              static_cast<unsigned>(a->mul_b));
	if (const auto *l = std::get_if<LoadImm>(&instr))
		return format("sig=14 mode=%u ", l->mode) + writes(*l) + format(" imm=0x%08x", l->value);
	if (const auto *s = std::get_if<Semaphore>(&instr))
		return "sig=14 mode=4 " + writes(*s) +
		       format(" sa=%u semaphore=%u ignored=0x%x", s->down, s->number, s->ignored);
	const auto &b = std::get<Branch>(instr);
	return format("sig=15 unused=%u cond_br=%u rel=%u reg=%u raddr_a=%u ws=%u waddr_add=%u "
	              "waddr_mul=%u imm=0x%08x",
	              b.ignored, static_cast<unsigned>(b.cond), b.rel, b.reg, b.raddr_a, b.ws,
	              b.waddr_add, b.waddr_mul, static_cast<uint32_t>(b.offset));
}

} // namespace frappe::vc4::isa
