// SPDX-License-Identifier: MIT
#include "asm/lint.hpp"

#include <optional>

#include "isa/disasm.hpp"
#include "isa/instr.hpp"

namespace frappe::vc4::qasm {

using namespace isa;

std::string Diagnostic::text() const
{
	return "instruction " + std::to_string(index) + ": " + message;
}

namespace {

// What one instruction reads and writes, whatever its format.
struct Access {
	bool alu = false;
	bool branch = false;
	Sig sig = Sig::None;
	// Writes as (file B?, waddr, conditional?) for each pipe that writes.
	struct Write {
		bool file_b;
		uint8_t waddr;
		bool conditional;
		Cond cond = Cond::Always;
	};
	std::vector<Write> writes;
	std::optional<uint8_t> read_a;
	std::optional<uint8_t> read_b;
	bool reads_acc[6] = {};
	bool rotates = false;
	bool rotate_r5 = false;
	bool rotate_reads_acc[4] = {};

	bool writesTo(uint8_t waddr) const
	{
		for (const auto &w : writes)
			if (w.waddr == waddr)
				return true;
		return false;
	}
	bool writesRegfile(bool file_b, uint8_t n) const
	{
		for (const auto &w : writes)
			if (w.waddr == n && w.file_b == file_b)
				return true;
		return false;
	}
	bool readsRaddr(uint8_t r) const { return read_a == r || read_b == r; }
};

bool used(Cond c) { return c != Cond::Never; }

Access analyse(uint64_t word)
{
	Access a;
	const Instr instr = decode(word);
	if (const auto *alu = std::get_if<Alu>(&instr)) {
		a.alu = true;
		a.sig = alu->sig;
		const bool add = alu->op_add != AddOp::Nop;
		const bool mul = alu->op_mul != MulOp::Nop;
		auto mux = [&](Mux m) {
			if (m == Mux::A)
				a.read_a = alu->raddr_a;
			else if (m == Mux::B && alu->sig != Sig::SmallImmediate)
				a.read_b = alu->raddr_b;
			else if (m <= Mux::R5)
				a.reads_acc[static_cast<unsigned>(m)] = true;
		};
		if (add) {
			mux(alu->add_a);
			if (!isUnary(alu->op_add))
				mux(alu->add_b);
			if (used(alu->cond_add))
				a.writes.push_back({alu->ws, alu->waddr_add, alu->cond_add != Cond::Always, alu->cond_add});
		}
		if (mul) {
			mux(alu->mul_a);
			mux(alu->mul_b);
			if (used(alu->cond_mul))
				a.writes.push_back({!alu->ws, alu->waddr_mul, alu->cond_mul != Cond::Always, alu->cond_mul});
			if (alu->sig == Sig::SmallImmediate && alu->raddr_b >= 48) {
				a.rotates = true;
				a.rotate_r5 = alu->raddr_b == 48;
				for (Mux m : {alu->mul_a, alu->mul_b})
					if (m <= Mux::R3)
						a.rotate_reads_acc[static_cast<unsigned>(m)] = true;
			}
		}
		// raddr fields read peripherals even when no mux selects them.
		if (alu->raddr_a >= 32 && alu->raddr_a != raddr::nop)
			a.read_a = alu->raddr_a;
		if (alu->sig != Sig::SmallImmediate && alu->raddr_b >= 32 && alu->raddr_b != raddr::nop)
			a.read_b = alu->raddr_b;
	} else if (const auto *b = std::get_if<Branch>(&instr)) {
		a.branch = true;
		a.sig = Sig::Branch;
		if (b->reg)
			a.read_a = b->raddr_a;
		if (b->waddr_add != waddr::nop)
			a.writes.push_back({b->ws, b->waddr_add, true});
		if (b->waddr_mul != waddr::nop)
			a.writes.push_back({!b->ws, b->waddr_mul, true});
	} else {
		const Writes &w = std::holds_alternative<LoadImm>(instr)
		                      ? static_cast<const Writes &>(std::get<LoadImm>(instr))
		                      : static_cast<const Writes &>(std::get<Semaphore>(instr));
		a.sig = Sig::LoadImmediate;
		if (used(w.cond_add) && w.waddr_add != waddr::nop)
			a.writes.push_back({w.ws, w.waddr_add, w.cond_add != Cond::Always});
		if (used(w.cond_mul) && w.waddr_mul != waddr::nop)
			a.writes.push_back({!w.ws, w.waddr_mul, w.cond_mul != Cond::Always});
	}
	return a;
}

bool isTmu(uint8_t w) { return w >= waddr::tmu0_s; }
bool isSfu(uint8_t w) { return w >= waddr::sfu_recip && w <= waddr::sfu_log2; }
bool isPeripheral(uint8_t w)
{
	return isTmu(w) || isSfu(w) || w == waddr::vpm_write || w == waddr::vpm_setup ||
	       w == waddr::dma_address || w == waddr::tmu_noswap || w == waddr::uniforms_address ||
	       w == waddr::mutex_release;
}

bool complementary(Cond a, Cond b)
{
	const auto x = static_cast<unsigned>(a), y = static_cast<unsigned>(b);
	return x >= 2 && y >= 2 && (x ^ 1) == y;
}

} // namespace

std::vector<Diagnostic> lint(std::span<const uint64_t> code, unsigned tmu_depth)
{
	std::vector<Diagnostic> out;
	std::vector<Access> acc;
	acc.reserve(code.size());
	for (uint64_t w : code)
		acc.push_back(analyse(w));
	auto report = [&](size_t i, Hazard h, std::string m) { out.push_back({i, h, std::move(m)}); };

	// Setups seen so far in program order (a linear approximation of reachability).
	bool read_setup_seen = false, write_setup_seen = false;
	int tmu_outstanding[2] = {0, 0};
	for (size_t i = 0; i < acc.size(); ++i) {
		const Access &cur = acc[i];
		const bool reads_vpm = cur.readsRaddr(raddr::vpm_read);
		bool vr_setup = false, vw_setup = false, vr_addr = false, vw_addr = false;
		for (const auto &w : cur.writes) {
			vr_setup |= w.waddr == waddr::vpm_setup && !w.file_b;
			vw_setup |= w.waddr == waddr::vpm_setup && w.file_b;
			vr_addr |= w.waddr == waddr::dma_address && !w.file_b;
			vw_addr |= w.waddr == waddr::dma_address && w.file_b;
		}
		// Addendum "Concurrent access to VPM registers": only a VPM read plus a VPM write
		// may share an instruction.
		if ((vr_setup || vw_setup) && (reads_vpm || cur.writesTo(waddr::vpm_write) || vr_addr || vw_addr))
			report(i, Hazard::VpmConcurrentAccess, "VPM setup together with another VPM access");
		if (reads_vpm && !read_setup_seen)
			report(i, Hazard::VpmReadWithoutSetup, "VPM read before any VPM read setup");
		if ((vr_addr && !read_setup_seen) || (vw_addr && !write_setup_seen))
			report(i, Hazard::DmaWithoutSetup, "DMA started before any VDR/VDW setup");
		read_setup_seen |= vr_setup;
		write_setup_seen |= vw_setup;
		// TMU requests retire on the S register; ldtmu pops one (program order only).
		// The depth is per QPU: the requests of both TMUs count together.
		for (const auto &w : cur.writes)
			if (w.waddr == waddr::tmu0_s || w.waddr == waddr::tmu1_s) {
				const int t = w.waddr == waddr::tmu1_s;
				if (++tmu_outstanding[t] + tmu_outstanding[1 - t] > static_cast<int>(tmu_depth))
					report(i, Hazard::TmuTooManyOutstanding,
					       "more than " + std::to_string(tmu_depth) + " TMU requests outstanding on the QPU");
			}
		if (cur.sig == Sig::LoadTmu0 || cur.sig == Sig::LoadTmu1) {
			int &n = tmu_outstanding[cur.sig == Sig::LoadTmu1];
			if (n == 0)
				report(i, Hazard::LdtmuWithoutRequest, "ldtmu with no TMU request outstanding");
			else
				--n;
		}
		const Access *prev = i ? &acc[i - 1] : nullptr;
		// Section 3 restrictions: "a regfile location cannot be read in the instruction
		// after it was written".
		if (prev) {
			if (cur.read_a && *cur.read_a < 32 && prev->writesRegfile(false, *cur.read_a))
				report(i, Hazard::RegfileReadAfterWrite, "reads ra" + std::to_string(*cur.read_a) + " written by the previous instruction");
			if (cur.read_b && *cur.read_b < 32 && prev->writesRegfile(true, *cur.read_b))
				report(i, Hazard::RegfileReadAfterWrite, "reads rb" + std::to_string(*cur.read_b) + " written by the previous instruction");
			for (unsigned r = 0; r < 4; ++r)
				if (cur.rotate_reads_acc[r] && prev->writesTo(static_cast<uint8_t>(waddr::r0 + r)))
					report(i, Hazard::RotateAfterWrite, "rotates r" + std::to_string(r) + " written by the previous instruction");
			if (cur.rotate_r5 && prev->writesTo(waddr::r5))
				report(i, Hazard::RotateR5AfterWrite, "rotation by r5 right after writing r5");
		}
		for (size_t k = 1; k <= 2 && k <= i; ++k)
			if (acc[i - k].writesTo(waddr::uniforms_address) && cur.readsRaddr(raddr::uniform))
				report(i, Hazard::UniformAfterAddressWrite, "uniform read within 2 instructions of a uniforms-address write");
		for (size_t k = 1; k <= 3 && k <= i; ++k)
			if (acc[i - k].writesTo(waddr::tmu_noswap))
				for (const auto &w : cur.writes)
					if (isTmu(w.waddr))
						report(i, Hazard::TmuAfterNoSwap, "TMU write within 3 instructions of tmu_noswap");
		for (size_t k = 1; k <= 2 && k <= i; ++k) {
			bool sfu = false;
			for (const auto &w : acc[i - k].writes)
				sfu |= isSfu(w.waddr);
			if (!sfu)
				continue;
			if (cur.reads_acc[4])
				report(i, Hazard::SfuResultTooEarly, "r4 read within 2 instructions of an SFU write");
			if (cur.sig == Sig::LoadTmu0 || cur.sig == Sig::LoadTmu1)
				report(i, Hazard::SfuResultTooEarly, "ldtmu while an SFU result is pending");
			for (const auto &w : cur.writes)
				if (isSfu(w.waddr))
					report(i, Hazard::SfuResultTooEarly, "SFU write while another SFU result is pending");
		}
		if ((cur.sig == Sig::LoadTmu0 || cur.sig == Sig::LoadTmu1) && cur.reads_acc[4])
			report(i, Hazard::R4ReadWithLdtmu, "r4 read in the instruction that loads it from the TMU");
		int tmu = 0, sfu = 0, setup = 0;
		for (const auto &w : cur.writes) {
			tmu += isTmu(w.waddr);
			sfu += isSfu(w.waddr);
			setup += w.waddr == waddr::vpm_setup;
			if (w.conditional && isPeripheral(w.waddr))
				report(i, Hazard::ConditionalPeripheral, "conditional write to " + isa::writeRegisterName(w.waddr, w.file_b));
		}
		if (tmu + sfu > 1 || setup > 1 || (cur.readsRaddr(raddr::mutex_acquire) && cur.writesTo(waddr::mutex_release)))
			report(i, Hazard::DoubleAccess, "more than one TMU/SFU/VPM-setup/mutex access in one instruction");
		// Both pipes may write one register only under complementary conditions, and never
		// a peripheral (addendum: "mov.ifz vpm, 0; mov.ifnz vpm, 1" writes undefined data).
		if (cur.writes.size() == 2 && cur.writes[0].waddr == cur.writes[1].waddr && cur.alu &&
		    (cur.writes[0].waddr >= 32 || cur.writes[0].file_b == cur.writes[1].file_b) &&
		    (isPeripheral(cur.writes[0].waddr) || !complementary(cur.writes[0].cond, cur.writes[1].cond)))
			report(i, Hazard::SameDestinationBothPipes, "ADD and MUL write the same register");
		if (cur.branch)
			for (size_t k = 1; k <= 2 && k <= i; ++k)
				if (acc[i - k].branch)
					report(i, Hazard::BranchTooClose, "fewer than 2 non-branch instructions since the previous branch");
		if (cur.sig == Sig::ProgramEnd) {
			for (const auto &w : cur.writes)
				if (w.waddr < 32)
					report(i, Hazard::ProgramEndWritesRegfile, "thread end instruction writes a register file");
			if (i + 2 >= acc.size())
				report(i, Hazard::ProgramEndTooShort, "thread end needs two delay-slot instructions");
			for (size_t k = 0; k <= 2 && i + k < acc.size(); ++k) {
				const Access &s = acc[i + k];
				if (s.readsRaddr(raddr::uniform) || s.readsRaddr(raddr::varying) ||
				    s.readsRaddr(raddr::vpm_read) || s.writesTo(waddr::vpm_write))
					report(i + k, Hazard::ProgramEndAccess, "uniform/varying/VPM access in the thread end or its delay slots");
				if (k > 0 && s.branch)
					report(i + k, Hazard::BranchInProgramEnd, "branch in a thread-end delay slot");
			}
		}
	}
	return out;
}

} // namespace frappe::vc4::qasm
