// SPDX-License-Identifier: MIT
#include "asm/text.hpp"

#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>

#include "asm/assembler.hpp"
#include "isa/disasm.hpp"
#include "isa/instr.hpp"

namespace frappe::vc4::qasm {

using namespace isa;

namespace {

std::string trim(const std::string &s)
{
	const auto b = s.find_first_not_of(" \t\r");
	if (b == std::string::npos)
		return {};
	const auto e = s.find_last_not_of(" \t\r");
	return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string &s, char sep)
{
	std::vector<std::string> out;
	std::string cur;
	int depth = 0;
	for (char c : s) {
		depth += c == '[' ? 1 : c == ']' ? -1 : 0;
		if (c == sep && depth == 0) {
			out.push_back(trim(cur));
			cur.clear();
		} else {
			cur += c;
		}
	}
	out.push_back(trim(cur));
	return out;
}

// "op.cond.setf.rot" -> parts
std::vector<std::string> dotted(const std::string &s) { return split(s, '.'); }

constexpr std::array<const char *, 8> kConds = {"never", "", "ifz", "ifnz", "ifn", "ifnn", "ifc", "ifcc"};
constexpr std::array<const char *, 16> kBranchConds = {
	"allz", "allnz", "anyz", "anynz", "alln", "allnn", "anyn", "anynn",
	"allc", "allnc", "anyc", "anync", "", "", "", ""};
constexpr std::array<const char *, 16> kPacks = {
	"", "16a", "16b", "8abcd", "8a", "8b", "8c", "8d",
	"32s", "16as", "16bs", "8abcds", "8as", "8bs", "8cs", "8ds"};
constexpr std::array<const char *, 8> kUnpacks = {"", "16a", "16b", "8dr", "8a", "8b", "8c", "8d"};
constexpr std::array<const char *, 14> kSignals = {
	"bkpt", "", "thrsw", "thrend", "sbwait", "sbdone", "lthrsw", "loadcv",
	"loadc", "ldcend", "ldtmu0", "ldtmu1", "loadam", ""};

template<size_t N>
int indexOf(const std::array<const char *, N> &table, const std::string &name)
{
	for (size_t i = 0; i < N; ++i)
		if (name == table[i] && !std::string(table[i]).empty())
			return static_cast<int>(i);
	return -1;
}

class Line {
public:
	Line(int number) : number_(number) {}
	[[noreturn]] void fail(const std::string &what) const
	{
		throw AsmError("line " + std::to_string(number_) + ": " + what);
	}

private:
	int number_;
};

// Splits "name.suffix" at the last dot when the suffix is a pack/unpack/cond name.
std::pair<std::string, std::string> suffix(const std::string &s)
{
	const auto dot = s.rfind('.');
	if (dot == std::string::npos || dot == 0 || s.find('/') != std::string::npos)
		return {s, ""};
	const std::string tail = s.substr(dot + 1);
	if (indexOf(kPacks, tail) >= 0 || indexOf(kUnpacks, tail) >= 0)
		return {s.substr(0, dot), tail};
	return {s, ""};
}

struct WriteReg {
	uint8_t waddr;
	int file; // 0 A, 1 B, -1 either
};

std::optional<WriteReg> writeReg(const std::string &name)
{
	if (name == "-")
		return WriteReg{waddr::nop, -1};
	if (name.size() > 2 && name[0] == 'r' && (name[1] == 'a' || name[1] == 'b') &&
	    std::isdigit(static_cast<unsigned char>(name[2]))) {
		const int n = std::atoi(name.c_str() + 2);
		if (n < 0 || n > 63)
			return std::nullopt;
		return WriteReg{static_cast<uint8_t>(n), name[1] == 'b'};
	}
	for (uint8_t w = 32; w < 64; ++w) {
		const std::string a = writeRegisterName(w, false), b = writeRegisterName(w, true);
		if (name == a || name == b)
			return WriteReg{w, a == b ? -1 : (name == b)};
	}
	return std::nullopt;
}

struct ReadReg {
	enum Kind { Acc, A, B, Either, Imm } kind;
	uint8_t value;
};

std::optional<ReadReg> readReg(const std::string &name)
{
	if (name.size() == 2 && name[0] == 'r' && name[1] >= '0' && name[1] <= '5')
		return ReadReg{ReadReg::Acc, static_cast<uint8_t>(name[1] - '0')};
	if (name.size() > 2 && name[0] == 'r' && (name[1] == 'a' || name[1] == 'b') &&
	    std::isdigit(static_cast<unsigned char>(name[2]))) {
		const int n = std::atoi(name.c_str() + 2);
		if (n < 0 || n > 63)
			return std::nullopt;
		return ReadReg{name[1] == 'a' ? ReadReg::A : ReadReg::B, static_cast<uint8_t>(n)};
	}
	for (uint8_t r = 32; r < 64; ++r) {
		const std::string a = readRegisterName(r, false), b = readRegisterName(r, true);
		if (name == a || name == b)
			return ReadReg{a == b ? ReadReg::Either : name == a ? ReadReg::A : ReadReg::B, r};
	}
	// Small immediates as the disassembler prints them.
	for (uint8_t code = 0; code < 48; ++code) {
		Alu probe;
		probe.sig = Sig::SmallImmediate;
		probe.op_add = isa::AddOp::Add;
		probe.add_b = Mux::B;
		probe.raddr_b = code;
		const std::string text = disassemble(encode(probe));
		if (text.substr(text.rfind(", ") + 2) == name)
			return ReadReg{ReadReg::Imm, code};
	}
	return std::nullopt;
}

uint32_t parseNumber(const Line &line, const std::string &s)
{
	char *end = nullptr;
	const long long v = std::strtoll(s.c_str(), &end, 0);
	if (s.empty() || *end != '\0')
		line.fail("bad number '" + s + "'");
	return static_cast<uint32_t>(v);
}

// Destination list of ldi/semaphore/branch: "-" or one or two registers with suffixes.
void parseDestinations(const Line &line, const std::vector<std::string> &dests, Writes &w,
                       bool allow_suffix)
{
	if (dests.size() > 2)
		line.fail("more than two destinations");
	bool first = true;
	for (const auto &d : dests) {
		if (d == "-") {
			// No write: the fields keep their defaults (waddr nop, cond never).
			first = false;
			continue;
		}
		auto parts = dotted(d);
		const auto reg = writeReg(parts[0]);
		if (!reg)
			line.fail("unknown destination '" + parts[0] + "'");
		Cond cond = Cond::Always;
		Pack pack = Pack::None;
		for (size_t i = 1; i < parts.size(); ++i) {
			if (!allow_suffix)
				line.fail("suffix on a branch destination");
			if (int c = indexOf(kConds, parts[i]); c >= 0)
				cond = static_cast<Cond>(c);
			else if (parts[i] == "never")
				cond = Cond::Never;
			else if (int p = indexOf(kPacks, parts[i]); p >= 0)
				pack = static_cast<Pack>(p);
			else
				line.fail("unknown suffix '" + parts[i] + "'");
		}
		if (first) {
			w.waddr_add = reg->waddr;
			w.cond_add = cond;
			w.ws = reg->file == 1;
			if (pack != Pack::None)
				w.pack = pack;
		} else {
			if (reg->file >= 0 && (reg->file == 0) != w.ws && reg->file != -1)
				w.ws = reg->file == 0;
			w.waddr_mul = reg->waddr;
			w.cond_mul = cond;
			if (pack != Pack::None) {
				w.pack = pack;
				w.pm = true;
			}
		}
		first = false;
	}
}

uint64_t parseLoad(const Line &line, const std::string &head, const std::vector<std::string> &args)
{
	auto parts = dotted(head);
	const bool setf = parts.size() > 1 && parts[1] == "setf";
	std::vector<std::string> dests(args.begin(), args.end() - 1);
	const std::string value = args.back();
	if (parts[0] == "sacq" || parts[0] == "srel") {
		Semaphore s;
		parseDestinations(line, dests, s, true);
		s.sf = setf;
		const uint32_t v = parseNumber(line, value);
		s.number = v & 15;
		s.down = parts[0] == "sacq";
		s.ignored = v >> 5;
		return encode(s);
	}
	LoadImm l;
	parseDestinations(line, dests, l, true);
	l.sf = setf;
	if (parts[0] == "ldi") {
		l.value = parseNumber(line, value);
	} else {
		const bool is_signed = parts[0] == "ldipes";
		l.mode = static_cast<uint8_t>(is_signed ? LoadMode::PerElementSigned : LoadMode::PerElementUnsigned);
		if (value.size() < 2 || value.front() != '[' || value.back() != ']')
			line.fail("per-element value needs [..]");
		const auto items = split(value.substr(1, value.size() - 2), ',');
		if (items.size() != 16)
			line.fail("per-element value needs 16 entries");
		for (unsigned e = 0; e < 16; ++e) {
			const auto bits = static_cast<uint32_t>(std::atoi(items[e].c_str())) & 3;
			l.value |= (bits & 1) << e | (bits >> 1) << (16 + e);
		}
	}
	return encode(l);
}

uint64_t parseBranch(const Line &line, const std::string &head, const std::vector<std::string> &args,
                     uint32_t address, const std::map<std::string, uint32_t> &labels)
{
	auto parts = dotted(head);
	Branch b;
	b.rel = parts[0] == "brr";
	b.cond = BranchCond::Always;
	if (parts.size() > 1) {
		const int c = indexOf(kBranchConds, parts[1]);
		if (c < 0)
			line.fail("unknown branch condition '" + parts[1] + "'");
		b.cond = static_cast<BranchCond>(c);
	}
	// vc4asm's operand counts: "dest, target", "dest, raN", "dest, raN, target", and
	// with a MUL link register "destA, destM, raN|-, target".
	auto isRegA = [](const std::string &s) { return s.size() > 2 && s[0] == 'r' && s[1] == 'a' && std::isdigit(static_cast<unsigned char>(s[2])); };
	size_t n = args.size();
	if (n < 2 || n > 4)
		line.fail("a branch takes 2 to 4 operands");
	std::string source, target;
	if (n == 2)
		(isRegA(args[1]) ? source : target) = args[1];
	else {
		source = args[n - 2];
		target = args[n - 1];
	}
	std::optional<uint8_t> reg;
	if (!source.empty() && source != "-") {
		if (!isRegA(source))
			line.fail("branch register must be ra0..ra31, got '" + source + "'");
		reg = static_cast<uint8_t>(std::atoi(source.c_str() + 2));
	}
	n = n == 4 ? 2 : 1;
	Writes w;
	parseDestinations(line, std::vector<std::string>(args.begin(), args.begin() + static_cast<long>(n)), w, false);
	b.ws = w.ws;
	b.waddr_add = w.waddr_add;
	b.waddr_mul = w.waddr_mul;
	if (reg) {
		b.reg = true;
		b.raddr_a = *reg & 31;
	}
	if (!target.empty()) {
		if (target.rfind("r:", 0) == 0 || target[0] == ':') {
			const std::string name = target.substr(target.find(':') + 1);
			auto it = labels.find(name);
			if (it == labels.end())
				line.fail("unknown label '" + name + "'");
			b.offset = static_cast<int32_t>(it->second) - (b.rel ? static_cast<int32_t>(address + 32) : 0);
		} else {
			b.offset = static_cast<int32_t>(parseNumber(line, target[0] == '+' ? target.substr(1) : target));
		}
	}
	return encode(b);
}

struct AluSide {
	bool used = false;
	std::string op;
	Cond cond = Cond::Always;
	bool setf = false;
	int rotate = -1; // small immediate code 48..63
	std::string dst;
	std::vector<std::string> srcs;
};

AluSide parseSide(const Line &line, const std::string &text)
{
	AluSide s;
	const auto space = text.find(' ');
	const std::string head = text.substr(0, space);
	std::string rest = space == std::string::npos ? "" : trim(text.substr(space + 1));
	auto parts = dotted(head);
	s.op = parts[0];
	for (size_t i = 1; i < parts.size(); ++i) {
		if (parts[i] == "setf")
			s.setf = true;
		else if (parts[i] == "rot") {
			// ".rot N," or ".rot r5," prefixes the operands.
			const auto comma = rest.find(',');
			const std::string n = trim(rest.substr(0, comma));
			s.rotate = n == "r5" ? 48 : 48 + static_cast<int>(parseNumber(line, n));
			rest = trim(rest.substr(comma + 1));
		} else if (parts[i] == "never")
			s.cond = Cond::Never;
		else if (int c = indexOf(kConds, parts[i]); c >= 0)
			s.cond = static_cast<Cond>(c);
		else
			line.fail("unknown modifier '" + parts[i] + "'");
	}
	if (s.op == "nop" && rest.empty())
		return s;
	s.used = true;
	auto ops = split(rest, ',');
	s.dst = ops[0];
	s.srcs.assign(ops.begin() + 1, ops.end());
	return s;
}

constexpr std::array<const char *, 32> kAddOps = {
	"nop", "fadd", "fsub", "fmin", "fmax", "fminabs", "fmaxabs", "ftoi",
	"itof", "", "", "", "add", "sub", "shr", "asr",
	"ror", "shl", "min", "max", "and", "or", "xor", "not",
	"clz", "", "", "", "", "", "av8adds", "av8subs"};
constexpr std::array<const char *, 8> kMulOps = {
	"nop", "fmul", "mul24", "v8muld", "v8min", "v8max", "v8adds", "v8subs"};

uint64_t parseAlu(const Line &line, const std::vector<std::string> &segments)
{
	// Segments in vc4asm's order: ops ("nop" takes the ADD slot first, MUL names the
	// MUL slot, as vc4asm assigns them), "read X" for register reads no input uses,
	// then a signal.
	Alu alu;
	AluSide add, mul;
	bool add_taken = false, mul_taken = false;
	std::vector<std::string> read_sources;
	for (const auto &segment : segments) {
		if (const int sig = indexOf(kSignals, segment); sig >= 0) {
			if (alu.sig != Sig::None)
				line.fail("second signal '" + segment + "'");
			alu.sig = static_cast<Sig>(sig);
			continue;
		}
		if (segment.rfind("read ", 0) == 0) {
			read_sources.push_back(trim(segment.substr(5)));
			continue;
		}
		if (alu.sig != Sig::None || !read_sources.empty())
			line.fail("op '" + segment + "' after a read or signal");
		AluSide side = parseSide(line, segment);
		const bool is_mul = indexOf(kMulOps, side.op) > 0;
		if (!is_mul && indexOf(kAddOps, side.op) < 0 && side.op != "nop")
			line.fail("unknown op '" + side.op + "'");
		if (side.op == "nop" ? !add_taken : !is_mul) {
			if (add_taken)
				line.fail("second ADD op '" + side.op + "'");
			add = side;
			add_taken = true;
		} else {
			if (mul_taken)
				line.fail("second MUL op '" + side.op + "'");
			mul = side;
			mul_taken = true;
		}
	}
	bool a_used = false, b_used = false, smi = false;
	auto source = [&](const std::string &text, bool consumer_is_mul) {
		(void)consumer_is_mul;
		auto [name, tail] = suffix(text);
		auto r = readReg(name);
		if (!r)
			line.fail("unknown source '" + text + "'");
		Mux m;
		switch (r->kind) {
		case ReadReg::Acc:
			m = static_cast<Mux>(r->value);
			break;
		case ReadReg::Imm:
			if (b_used && (!smi || alu.raddr_b != r->value))
				line.fail("second read on port B");
			b_used = smi = true;
			alu.raddr_b = r->value;
			m = Mux::B;
			break;
		case ReadReg::B:
			if (b_used && (smi || alu.raddr_b != r->value))
				line.fail("second read on port B");
			b_used = true;
			alu.raddr_b = r->value;
			m = Mux::B;
			break;
		default:
			if (r->kind == ReadReg::Either && a_used && alu.raddr_a != r->value) {
				b_used = true;
				alu.raddr_b = r->value;
				m = Mux::B;
				break;
			}
			if (a_used && alu.raddr_a != r->value)
				line.fail("second read on port A");
			a_used = true;
			alu.raddr_a = r->value;
			m = Mux::A;
		}
		if (!tail.empty()) {
			const int u = indexOf(kUnpacks, tail);
			if (u < 0)
				line.fail("unknown unpack '" + tail + "'");
			alu.unpack = static_cast<Unpack>(u);
			alu.pm = m == Mux::R4;
		}
		return m;
	};
	int add_file = -1, mul_file = -1;
	Pack add_pack = Pack::None, mul_pack = Pack::None;
	if (add.used) {
		const int op = indexOf(kAddOps, add.op);
		if (op < 0)
			line.fail("unknown ADD op '" + add.op + "'");
		alu.op_add = static_cast<isa::AddOp>(op);
		alu.cond_add = add.cond;
		auto [name, tail] = suffix(add.dst);
		auto w = writeReg(name);
		if (!w)
			line.fail("unknown destination '" + add.dst + "'");
		alu.waddr_add = w->waddr;
		add_file = w->file;
		if (!tail.empty())
			add_pack = static_cast<Pack>(std::max(0, indexOf(kPacks, tail)));
		if (add.srcs.empty())
			line.fail("missing ADD operands");
		// A unary op has one operand; vc4asm leaves add_b at r0.
		const size_t operands = isUnary(alu.op_add) ? 1 : 2;
		if (add.srcs.size() != operands)
			line.fail(add.op + " takes " + std::to_string(operands) + " operand(s)");
		alu.add_a = source(add.srcs[0], false);
		if (operands == 2)
			alu.add_b = source(add.srcs[1], false);
	}
	if (mul.used) {
		const int op = indexOf(kMulOps, mul.op);
		if (op < 0)
			line.fail("unknown MUL op '" + mul.op + "'");
		alu.op_mul = static_cast<isa::MulOp>(op);
		alu.cond_mul = mul.cond;
		auto [name, tail] = suffix(mul.dst);
		auto w = writeReg(name);
		if (!w)
			line.fail("unknown destination '" + mul.dst + "'");
		alu.waddr_mul = w->waddr;
		mul_file = w->file;
		if (!tail.empty())
			mul_pack = static_cast<Pack>(std::max(0, indexOf(kPacks, tail)));
		if (mul.srcs.size() != 2)
			line.fail("MUL needs two operands");
		alu.mul_a = source(mul.srcs[0], true);
		alu.mul_b = source(mul.srcs[1], true);
		if (mul.rotate >= 0) {
			if (b_used && (!smi || alu.raddr_b != mul.rotate))
				line.fail("rotation needs the small immediate field");
			smi = true;
			alu.raddr_b = static_cast<uint8_t>(mul.rotate);
		}
	}
	for (const auto &text : read_sources) {
		const Mux m = source(text, false);
		if (m != Mux::A && m != Mux::B)
			line.fail("read needs a register file or small immediate, got '" + text + "'");
	}
	if (smi) {
		if (alu.sig != Sig::None)
			line.fail("signal with a small immediate");
		alu.sig = Sig::SmallImmediate;
	}
	alu.sf = add.used ? add.setf : mul.setf;
	// ws = 1 when the ADD writes file B or the MUL writes file A.
	alu.ws = add_file == 1 || mul_file == 0;
	if (add_pack != Pack::None)
		alu.pack = add_pack;
	if (mul_pack != Pack::None) {
		alu.pack = mul_pack;
		alu.pm = !(alu.ws && mul_file == 0 && alu.waddr_mul < 32);
	}
	return encode(alu);
}

// 32-bit units of one value of a data directive: ".int" 1, ".long" 2, not data 0.
int dataUnits(const std::string &line)
{
	const std::string head = line.substr(0, line.find_first_of(" \t"));
	return head == ".int" ? 1 : head == ".long" ? 2 : 0;
}

uint64_t parseData(const Line &line, const std::string &s, int units)
{
	char *end = nullptr;
	errno = 0;
	const unsigned long long v = std::strtoull(s.c_str(), &end, 0);
	if (s.empty() || *end != '\0' || s[0] == '-' || errno || (units == 1 && v > 0xffffffffull))
		line.fail("bad " + std::string(units == 1 ? ".int" : ".long") + " value '" + s + "'");
	return v;
}

} // namespace

std::vector<uint64_t> assembleText(const std::string &text)
{
	// Two passes: labels first. Addresses count 32-bit units so that data (".int" 32
	// bits, ".long" 64 bits as in vc4asm) can hold any number of words; instructions and
	// labels must sit on 64-bit boundaries.
	struct Entry {
		int number;
		std::string text;
	};
	std::vector<Entry> lines;
	std::map<std::string, uint32_t> labels;
	{
		std::istringstream in(text);
		std::string raw;
		int number = 0;
		uint32_t units = 0;
		while (std::getline(in, raw)) {
			++number;
			if (auto c = raw.find('#'); c != std::string::npos)
				raw.resize(c);
			const std::string l = trim(raw);
			if (l.empty())
				continue;
			const int data = dataUnits(l);
			if (!data && units % 2)
				Line(number).fail("instruction or label after an odd number of .int words");
			if (l[0] == ':') {
				labels[l.substr(1)] = units * 4;
				continue;
			}
			units += data ? static_cast<uint32_t>(data * split(l.substr(l.find_first_of(" \t") + 1), ',').size()) : 2;
			lines.push_back({number, l});
		}
		if (units % 2)
			Line(number).fail("odd number of .int words at the end");
	}
	std::vector<uint64_t> code;
	std::vector<uint32_t> data;
	for (const auto &[number, l] : lines) {
		const Line line(number);
		const auto space = l.find_first_of(" \t");
		const std::string head = l.substr(0, space);
		const std::string op = dotted(head)[0];
		const auto address = static_cast<uint32_t>(code.size() * 8);
		const std::string rest = space == std::string::npos ? "" : trim(l.substr(space + 1));
		if (const int units = dataUnits(l)) {
			for (const auto &v : split(rest, ',')) {
				const uint64_t value = parseData(line, v, units);
				data.push_back(static_cast<uint32_t>(value));
				if (units == 2)
					data.push_back(static_cast<uint32_t>(value >> 32));
			}
			for (; data.size() >= 2; data.erase(data.begin(), data.begin() + 2))
				code.push_back(uint64_t{data[0]} | uint64_t{data[1]} << 32);
		} else if (op == "bra" || op == "brr") {
			code.push_back(parseBranch(line, head, split(rest, ','), address, labels));
		} else if (op == "ldi" || op == "ldipes" || op == "ldipeu" || op == "sacq" || op == "srel") {
			code.push_back(parseLoad(line, head, split(rest, ',')));
		} else {
			code.push_back(parseAlu(line, split(l, ';')));
		}
	}
	return code;
}

} // namespace frappe::vc4::qasm
