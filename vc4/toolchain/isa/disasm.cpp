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
	"clz", "addop25?", "addop26?", "addop27?", "addop28?", "addop29?", "v8adds", "v8subs",
};
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

std::string sourceName(const Alu &i, Mux mux)
{
	std::string s;
	switch (mux) {
	case Mux::A:
		s = pinnedReadName(i.raddr_a, false);
		break;
	case Mux::B:
		if (i.sig == Sig::SmallImmediate)
			s = i.raddr_b < 48 ? kSmallImm[i.raddr_b]
			                   : format("%d", static_cast<int>(i.raddr_b) - 64);
		else
			s = pinnedReadName(i.raddr_b, true);
		break;
	default:
		s = format("r%u", static_cast<unsigned>(mux));
	}
	if ((!i.pm && mux == Mux::A) || (i.pm && mux == Mux::R4))
		s += kUnpack[static_cast<unsigned>(i.unpack)];
	return s;
}

// Destination names of the ADD and MUL writes. When ws = 1 and both names are shared
// between the files, the ADD name is pinned so that vc4asm sets ws again.
std::array<std::string, 2> destNames(bool ws, uint8_t waddr_add, uint8_t waddr_mul,
                                     bool add_used, bool mul_used)
{
	std::string add = writeRegisterName(waddr_add, ws);
	std::string mul = writeRegisterName(waddr_mul, !ws);
	const bool add_decides = add_used && !writeNameIsShared(waddr_add);
	const bool mul_decides = mul_used && !writeNameIsShared(waddr_mul);
	if (ws && !add_decides && !mul_decides) {
		if (add_used)
			add = format("rb%u", waddr_add);
		else if (mul_used)
			mul = format("ra%u", waddr_mul);
	}
	return {add, mul};
}

std::string disassembleAlu(const Alu &i)
{
	const bool add_used = i.op_add != AddOp::Nop;
	const bool mul_used = i.op_mul != MulOp::Nop;
	const auto dst = destNames(i.ws, i.waddr_add, i.waddr_mul, add_used, mul_used);
	std::string out;
	if (!add_used) {
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
		if (!isUnary(i.op_add) || i.add_b != i.add_a)
			out += ", " + sourceName(i, i.add_b);
	}
	if (mul_used) {
		out += "; ";
		out += kMulOps[static_cast<unsigned>(i.op_mul)];
		out += kConds[static_cast<unsigned>(i.cond_mul)];
		if (i.sf && !add_used)
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

// Destinations of ldi/semaphore/branch: each present one, with pack and condition.
std::string writeList(const Writes &w, bool with_pack_cond)
{
	const auto dst = destNames(w.ws, w.waddr_add, w.waddr_mul, w.waddr_add != waddr::nop,
	                           w.waddr_mul != waddr::nop);
	std::string out;
	if (w.waddr_add != waddr::nop) {
		out += dst[0];
		if (with_pack_cond) {
			if (!w.pm)
				out += kPackA[static_cast<unsigned>(w.pack)];
			out += kConds[static_cast<unsigned>(w.cond_add)];
		}
		out += ", ";
	}
	if (w.waddr_mul != waddr::nop) {
		out += dst[1];
		if (with_pack_cond) {
			if (w.pm)
				out += kPackMul[static_cast<unsigned>(w.pack)];
			out += kConds[static_cast<unsigned>(w.cond_mul)];
		}
		out += ", ";
	}
	if (out.empty())
		out = "-, ";
	return out;
}

std::string disassembleLoad(const LoadImm &i)
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

std::string disassembleSemaphore(const Semaphore &i)
{
	std::string out = i.down ? "sacq" : "srel";
	if (i.sf)
		out += ".setf";
	out += ' '; out += writeList(i, true);
	out += immediateText(i.number | (i.ignored << 5));
	return out;
}

std::string disassembleBranch(const Branch &i, const std::string &target)
{
	std::string out = i.rel ? "brr" : "bra";
	out += kBranchConds[static_cast<unsigned>(i.cond)];
	Writes w;
	w.ws = i.ws;
	w.waddr_add = i.waddr_add;
	w.waddr_mul = i.waddr_mul;
	out += ' '; out += writeList(w, false);
	if (i.reg) {
		out += readRegisterName(i.raddr_a, false);
		if (i.offset != 0 || !target.empty())
			out += ", ";
	}
	if (!target.empty())
		out += target;
	else if (i.offset != 0 || !i.reg)
		out += i.rel ? format("%+d", i.offset) : format("0x%x", static_cast<uint32_t>(i.offset));
	return out;
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

std::string disassemble(uint64_t word)
{
	const Instr instr = decode(word);
	if (const auto *a = std::get_if<Alu>(&instr))
		return disassembleAlu(*a);
	if (const auto *l = std::get_if<LoadImm>(&instr))
		return disassembleLoad(*l);
	if (const auto *s = std::get_if<Semaphore>(&instr))
		return disassembleSemaphore(*s);
	return disassembleBranch(std::get<Branch>(instr), {});
}

std::string disassembleProgram(std::span<const uint64_t> words, bool with_comments)
{
	// Relative targets count from the fourth instruction after the branch (section 3
	// "Branches": PC + 4 instructions).
	std::map<uint32_t, std::string> labels;
	const auto size = static_cast<uint32_t>(words.size() * 8);
	for (size_t n = 0; n < words.size(); ++n) {
		const Instr instr = decode(words[n]);
		const auto *b = std::get_if<Branch>(&instr);
		if (!b || !b->rel || b->reg)
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
		std::string text;
		const Instr instr = decode(words[n]);
		if (const auto *b = std::get_if<Branch>(&instr); b && b->rel && !b->reg) {
			const int64_t target = static_cast<int64_t>(address) + 32 + b->offset;
			auto it = target >= 0 ? labels.find(static_cast<uint32_t>(target)) : labels.end();
			text = disassembleBranch(*b, it != labels.end() ? "r:" + it->second : std::string{});
		} else {
			text = disassemble(words[n]);
		}
		if (with_comments)
			out << '\t' << format("%-56s", text.c_str())
			    << format(" # %04x: %016" PRIx64, address, words[n]) << '\n';
		else
			out << '\t' << text << '\n';
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
