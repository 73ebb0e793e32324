// SPDX-License-Identifier: MIT
#include "emu/v3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "emu/alu.hpp"
#include "emu/tmu.hpp"
#include "isa/instr.hpp"
#include "isa/setup_words.hpp"

namespace frappe::vc4::emu {

using namespace isa;
using Mask = std::array<bool, kLanes>;

namespace {
std::string hex(uint32_t v)
{
	char buf[16];
	std::snprintf(buf, sizeof(buf), "0x%08x", v);
	return buf;
}
Vec broadcast(uint32_t v)
{
	Vec out;
	out.fill(v);
	return out;
}
constexpr Mask kAll = {true, true, true, true, true, true, true, true,
                       true, true, true, true, true, true, true, true};
} // namespace

Fault::Fault(int q, uint32_t p, const std::string &what)
	: std::runtime_error("QPU " + std::to_string(q) + " at " + hex(p) + ": " + what), qpu(q), pc(p)
{
}

V3d::V3d(Memory &memory, Config config)
	: memory_(memory), config_(config), vpm_(config.vpm_rows * 16)
{
	for (unsigned i = 0; i < kQpus; ++i)
		qpus_.push_back(std::make_unique<Qpu>(*this, i));
}

V3d::~V3d() = default;

uint32_t &V3d::vpm(unsigned row, unsigned column) { return vpm_.at(row * 16 + column); }

const Qpu &V3d::qpu(unsigned n) const { return *qpus_.at(n); }

LaunchStats V3d::launch(std::span<const Job> jobs, LaunchOptions options)
{
	if (jobs.size() > kQpus)
		throw std::invalid_argument("at most 12 QPU jobs per launch");
	semaphores_.fill(0);
	semaphore_release_cycle_.fill(0);
	mutex_owner_ = -1;
	mutex_release_cycle_ = 0;
	for (size_t i = 0; i < jobs.size(); ++i)
		qpus_[i]->start(jobs[i]);

	std::mt19937_64 rng(options.seed);
	std::vector<unsigned> live;
	uint64_t total = 0;
	size_t cursor = 0;
	unsigned blocked_in_a_row = 0;
	while (true) {
		live.clear();
		for (size_t i = 0; i < jobs.size(); ++i)
			if (!qpus_[i]->halted())
				live.push_back(static_cast<unsigned>(i));
		if (live.empty())
			break;
		unsigned pick;
		if (options.schedule == Schedule::RoundRobin) {
			cursor %= jobs.size();
			while (qpus_[cursor]->halted())
				cursor = (cursor + 1) % jobs.size();
			pick = static_cast<unsigned>(cursor);
			cursor = (cursor + 1) % jobs.size();
		} else {
			pick = live[std::uniform_int_distribution<size_t>(0, live.size() - 1)(rng)];
		}
		const Qpu::Step s = qpus_[pick]->step();
		if (s == Qpu::Step::Blocked) {
			// Every live QPU blocked many times over with no progress: a deadlock.
			if (++blocked_in_a_row > 64 * live.size())
				throw Fault(static_cast<int>(pick), qpus_[pick]->pc(),
				            "deadlock: every running QPU waits on a semaphore or the mutex");
			continue;
		}
		blocked_in_a_row = 0;
		if (++total > config_.max_instructions)
			throw Fault(static_cast<int>(pick), qpus_[pick]->pc(), "instruction limit reached");
	}

	LaunchStats stats;
	for (size_t i = 0; i < jobs.size(); ++i) {
		const QpuStats &q = qpus_[i]->stats();
		stats.qpus.push_back(q);
		stats.instructions += q.instructions;
		stats.cycles = std::max(stats.cycles, q.cycles);
		stats.host_interrupts += q.host_interrupts;
		stats.traffic += q.traffic;
	}
	return stats;
}

Qpu::Qpu(V3d &v3d, unsigned id) : v3d_(&v3d), id_(id) {}

void Qpu::start(const Job &job)
{
	*this = Qpu(*v3d_, id_);
	pc_ = job.code;
	uniforms_ = job.uniforms;
	halted_ = false;
}

void Qpu::fault(const std::string &what) const { throw Fault(static_cast<int>(id_), pc_, what); }

// Section 3 "Condition Codes": Table 1 cond_add / cond_mul.
bool Qpu::cond(uint8_t code, unsigned lane) const
{
	switch (static_cast<Cond>(code)) {
	case Cond::Never: return false;
	case Cond::Always: return true;
	case Cond::ZSet: return z_[lane];
	case Cond::ZClear: return !z_[lane];
	case Cond::NSet: return n_[lane];
	case Cond::NClear: return !n_[lane];
	case Cond::CSet: return c_[lane];
	case Cond::CClear: return !c_[lane];
	}
	return false;
}

// Section 3 "Branches": all/any of Z, N or C set/clear over the 16 lanes.
bool Qpu::branchTaken(uint8_t code) const
{
	if (code == 15)
		return true;
	if (code > 11)
		return false; // 12-14 are not documented
	const auto &flags = code < 4 ? z_ : code < 8 ? n_ : c_;
	const bool any = (code >> 1) & 1;
	const bool clear = code & 1;
	unsigned count = 0;
	for (bool f : flags)
		count += f != clear;
	return any ? count > 0 : count == kLanes;
}

uint32_t Qpu::popUniform()
{
	if (v3d_->config_.strict && unif_addr_slots_ > 0)
		fault("uniform read within 2 instructions of a uniforms-address write");
	const uint32_t v = v3d_->memory_.read32(uniforms_);
	uniforms_ += 4;
	stats_.traffic.uniform_read += 4;
	return v;
}

bool Qpu::wouldBlock(uint8_t raddr, bool) const
{
	return raddr == raddr::mutex_acquire && v3d_->mutex_owner_ >= 0;
}

Vec Qpu::read(uint8_t raddr, bool file_b)
{
	if (raddr < 32) {
		if (v3d_->config_.strict && ((file_b ? written_b_ : written_a_) >> raddr & 1))
			fault(std::string("reads r") + (file_b ? 'b' : 'a') + std::to_string(raddr) +
			      " written by the previous instruction");
		return file_b ? rb_[raddr] : ra_[raddr];
	}
	switch (raddr) {
	case raddr::uniform:
		return broadcast(popUniform());
	case raddr::element_number:
		if (file_b)
			return broadcast(id_);
		{
			Vec v;
			for (unsigned i = 0; i < kLanes; ++i)
				v[i] = i;
			return v;
		}
	case raddr::nop:
		return broadcast(0);
	case raddr::vpm_read:
		return vpmRead();
	case raddr::vdr_busy:
		return broadcast(clock() < (file_b ? vdw_done_ : vdr_done_));
	case raddr::vdr_wait: {
		const uint64_t done = file_b ? vdw_done_ : vdr_done_;
		if (done > clock()) {
			stats_.stall_cycles += done - clock();
			stats_.cycles = done;
		}
		return broadcast(0);
	}
	case raddr::mutex_acquire:
		v3d_->mutex_owner_ = static_cast<int>(id_);
		if (v3d_->mutex_release_cycle_ > clock()) {
			stats_.stall_cycles += v3d_->mutex_release_cycle_ - clock();
			stats_.cycles = v3d_->mutex_release_cycle_;
		}
		return broadcast(0);
	default:
		fault("read of " + std::to_string(raddr) + (file_b ? " (B)" : " (A)") +
		      ": not available to user programs");
	}
}

void Qpu::setFlags(const std::array<uint32_t, kLanes> &value, const std::array<bool, kLanes> &carry,
                   const Mask &mask, bool float_op)
{
	for (unsigned i = 0; i < kLanes; ++i) {
		if (!mask[i])
			continue;
		z_[i] = zeroFlag(value[i], float_op);
		n_[i] = negativeFlag(value[i], float_op);
		c_[i] = carry[i];
	}
}

void Qpu::write(uint8_t waddr, bool file_b, const Vec &value, const Mask &mask, bool conditional)
{
	if (waddr < 32) {
		auto &reg = file_b ? rb_[waddr] : ra_[waddr];
		for (unsigned i = 0; i < kLanes; ++i)
			if (mask[i])
				reg[i] = value[i];
		(file_b ? writing_b_ : writing_a_) |= 1u << waddr;
		return;
	}
	if (waddr <= waddr::r3) {
		for (unsigned i = 0; i < kLanes; ++i)
			if (mask[i])
				acc_[waddr - 32][i] = value[i];
		return;
	}
	if (waddr == waddr::nop)
		return;
	if (waddr == waddr::r5) {
		// Addendum "Writing to r5": file A replicates per quad (elements 0, 4, 8, 12),
		// file B replicates element 0.
		for (unsigned i = 0; i < kLanes; ++i)
			if (mask[i])
				acc_[5][i] = file_b ? value[0] : value[i & ~3u];
		return;
	}
	// Addendum "No conditional write to peripheral registers": a conditional TMU, VPM or
	// SFU write triggers the unit with undefined data in the unselected lanes.
	const bool per_lane = waddr == waddr::vpm_write || waddr >= waddr::sfu_recip;
	if (conditional && per_lane && v3d_->config_.strict)
		fault("conditional write to peripheral register " + std::to_string(waddr));
	// The other peripherals take element 0 (addendum for host_int; assumed for the rest).
	if (!per_lane && !mask[0])
		return;
	switch (waddr) {
	case waddr::tmu_noswap:
		tmu_noswap_ = value[0] != 0; // addendum: only element 0 counts
		return;
	case waddr::host_int:
		if (value[0] != 0) // addendum: a zero write does nothing
			++stats_.host_interrupts;
		return;
	case waddr::uniforms_address:
		uniforms_ = value[0];
		unif_addr_slots_ = 3; // counts down after this instruction: 2 instructions blocked
		return;
	case waddr::vpm_write:
		vpmWrite(value);
		return;
	case waddr::vpm_setup:
		vpmSetup(file_b, value[0]);
		return;
	case waddr::dma_address:
		dmaStart(file_b, value[0]);
		return;
	case waddr::mutex_release:
		if (v3d_->mutex_owner_ != static_cast<int>(id_) && v3d_->config_.strict)
			fault("mutex released by a QPU that does not hold it");
		v3d_->mutex_owner_ = -1;
		v3d_->mutex_release_cycle_ = clock();
		return;
	case waddr::sfu_recip:
	case waddr::sfu_recipsqrt:
	case waddr::sfu_exp2:
	case waddr::sfu_log2: {
		// Section 3 "Special Functions Unit": result in r4 after two instructions; the
		// precision is not documented, so these are exact float results.
		Vec result;
		for (unsigned i = 0; i < kLanes; ++i) {
			const float x = toFloat(value[i]);
			float r;
			switch (waddr) {
			case waddr::sfu_recip: r = 1.0f / x; break;
			case waddr::sfu_recipsqrt: r = 1.0f / std::sqrt(x); break;
			case waddr::sfu_exp2: r = std::exp2(x); break;
			default: r = std::log2(x); break;
			}
			result[i] = fromFloat(r);
		}
		sfu_pending_.push_back({4, result});
		return;
	}
	default:
		if (waddr >= waddr::tmu0_s) {
			const unsigned t = (waddr - waddr::tmu0_s) / 4;
			tmuWrite(t, (waddr - waddr::tmu0_s) % 4, value);
			return;
		}
		fault("write to " + std::to_string(waddr) + ": not available to user programs");
	}
}

// Section 4 "TMU": writing S retires the request; without a preceding T/R/B write in
// the request it is a general-memory (direct) lookup of 32-bit words.
void Qpu::tmuWrite(unsigned tmu, unsigned reg, const Vec &v)
{
	TmuRequest &req = tmu_request_[tmu];
	if (reg != 0) {
		(reg == 1 ? req.t : reg == 2 ? req.r : req.b) = v;
		req.coords_written = true;
		return;
	}
	auto &fifo = tmu_fifo_[tmu];
	const size_t in_flight = fifo.size() + tmu_fifo_[1 - tmu].size();
	if (v3d_->config_.strict && in_flight >= v3d_->config_.tmu_fifo_limit)
		fault("more than " + std::to_string(in_flight) + " TMU requests outstanding on the QPU");
	if (fifo.size() >= 8)
		fault("more than 8 requests outstanding on TMU" + std::to_string(tmu));
	TmuResult result{{}, clock() + v3d_->config_.timing.tmu_latency};
	stats_.traffic.tmu_read += 4 * kLanes;
	if (!req.coords_written) {
		for (unsigned i = 0; i < kLanes; ++i)
			result.value[i] = v3d_->memory_.read32(v[i] & ~3u);
	} else {
		// The TMU reads its config parameters from this QPU's uniform stream.
		const uint32_t p0 = popUniform();
		const uint32_t p1 = popUniform();
		const TextureConfig tex = TextureConfig::fromUniforms(p0, p1);
		try {
			for (unsigned i = 0; i < kLanes; ++i)
				result.value[i] = sampleTexture(v3d_->memory_, tex, toFloat(v[i]), toFloat(req.t[i]),
				                                v3d_->config_.bilinear_fraction_bits);
		} catch (const std::runtime_error &e) {
			fault(e.what());
		}
	}
	fifo.push_back(result);
	req = {};
}

// Section 7, Table 32/33 generic block access. Horizontal 32-bit rows, vertical 32-bit
// columns (ADDR = Y[7:4] block of 16 rows, X[3:0] column), and horizontal laned 8/16-bit.
namespace {
uint32_t *vpmWord(std::vector<uint32_t> &vpm, unsigned rows, unsigned addr, bool horizontal,
                  VpmSize size, unsigned lane, unsigned &shift, unsigned &bits, int qpu, uint32_t pc)
{
	unsigned row, column;
	shift = 0;
	bits = 32;
	if (size == VpmSize::Bits32) {
		if (horizontal) {
			row = addr;
			column = lane;
		} else {
			row = (addr >> 4) * 16 + lane;
			column = addr & 15;
		}
	} else if (horizontal) {
		const unsigned per_word = size == VpmSize::Bits8 ? 4 : 2;
		row = addr / per_word;
		column = lane;
		bits = size == VpmSize::Bits8 ? 8 : 16;
		shift = (addr % per_word) * bits;
	} else {
		throw Fault(qpu, pc, "vertical 8/16-bit VPM access is not modelled");
	}
	if (row >= rows)
		throw Fault(qpu, pc, "VPM address beyond the VPM");
	return &vpm[row * 16 + column];
}
} // namespace

void Qpu::vpmWrite(const Vec &v)
{
	const auto s = VpmWriteSetup::fromWord(vpm_write_setup_);
	for (unsigned i = 0; i < kLanes; ++i) {
		unsigned shift, bits;
		uint32_t *w = vpmWord(v3d_->vpm_, v3d_->config_.vpm_rows, vpm_write_addr_, s.horizontal,
		                      s.size, i, shift, bits, static_cast<int>(id_), pc_);
		const uint32_t mask = bits == 32 ? ~0u : ((1u << bits) - 1) << shift;
		*w = (*w & ~mask) | ((v[i] << shift) & mask);
	}
	vpm_write_addr_ = (vpm_write_addr_ + (s.stride ? s.stride : 64)) & 255;
}

Vec Qpu::vpmRead()
{
	if (!vpm_read_fifo_.empty()) {
		Vec v = vpm_read_fifo_.front();
		vpm_read_fifo_.erase(vpm_read_fifo_.begin());
		return v;
	}
	if (vpm_read_left_ == 0)
		fault("VPM read with no read setup outstanding (the hardware would block forever)");
	const auto s = VpmReadSetup::fromWord(vpm_read_setup_);
	Vec v;
	for (unsigned i = 0; i < kLanes; ++i) {
		unsigned shift, bits;
		const uint32_t *w = vpmWord(v3d_->vpm_, v3d_->config_.vpm_rows, vpm_read_addr_, s.horizontal,
		                            s.size, i, shift, bits, static_cast<int>(id_), pc_);
		v[i] = bits == 32 ? *w : (*w >> shift) & ((1u << bits) - 1);
	}
	vpm_read_addr_ = (vpm_read_addr_ + (s.stride ? s.stride : 64)) & 255;
	--vpm_read_left_;
	return v;
}

void Qpu::vpmSetup(bool write, uint32_t word)
{
	if (write) {
		switch (vwSetupKind(word)) {
		case SetupKind::VpmGeneric:
			vpm_write_setup_ = word;
			vpm_write_addr_ = word & 255;
			return;
		case SetupKind::VdwBasic: vdw_setup_ = word; return;
		case SetupKind::VdwStride: vdw_stride_ = word; return;
		default: fault("unknown VPM write setup " + hex(word));
		}
	}
	switch (vrSetupKind(word)) {
	case SetupKind::VpmGeneric:
		// Addendum: read setups cannot be queued; a new one is accepted only when at most
		// one value of the previous one is outstanding (that value is already fetched).
		if (vpm_read_left_ > 1) {
			if (v3d_->config_.strict)
				fault("VPM read setup while more than one read of the previous setup is outstanding");
			return;
		}
		if (vpm_read_left_ == 1)
			vpm_read_fifo_.push_back(vpmRead());
		vpm_read_setup_ = word;
		vpm_read_addr_ = word & 255;
		vpm_read_left_ = (word >> 20) & 15;
		if (vpm_read_left_ == 0)
			vpm_read_left_ = 16;
		return;
	case SetupKind::VdrBasic: vdr_setup_ = word; return;
	case SetupKind::VdrStride: vdr_pitch_ = word; return;
	default: fault("unknown VPM read setup " + hex(word));
	}
}

// Section 7 "VCD DMA": 32-bit transfers between memory rows and VPM rows (horizontal) or
// columns (vertical). The copy happens at once; the wait registers stall until the
// modelled completion time.
void Qpu::dmaStart(bool store, uint32_t address)
{
	const Timing &t = v3d_->config_.timing;
	auto &vpm = v3d_->vpm_;
	const unsigned rows_total = v3d_->config_.vpm_rows;
	auto vpmAt = [&](unsigned row, unsigned column) -> uint32_t & {
		if (row >= rows_total || column >= 16)
			fault("DMA beyond the VPM");
		return vpm[row * 16 + column];
	};
	unsigned rows, words;
	if (store) {
		const auto s = VdwSetup::fromWord(vdw_setup_);
		if (vwSetupKind(vdw_setup_) != SetupKind::VdwBasic)
			fault("VDW started without a VDW setup");
		if (s.modew != 0)
			fault("8/16-bit VDW is not modelled");
		rows = s.units ? s.units : 128;
		words = s.depth ? s.depth : 128;
		const uint32_t stride = VdwStride::fromWord(vdw_stride_).stride;
		const unsigned y = s.vpm_base >> 4, x = s.vpm_base & 15;
		for (unsigned r = 0; r < rows; ++r) {
			const uint32_t row_address = address + r * (words * 4 + stride);
			for (unsigned w = 0; w < words; ++w) {
				const uint32_t value = s.horizontal ? vpmAt(y + r + (x + w) / 16, (x + w) % 16)
				                                    : vpmAt(y + w, x + r);
				v3d_->memory_.write32(row_address + w * 4, value);
			}
		}
	} else {
		const auto s = VdrSetup::fromWord(vdr_setup_);
		if (vrSetupKind(vdr_setup_) != SetupKind::VdrBasic)
			fault("VDR started without a VDR setup");
		if (s.modew != 0)
			fault("8/16-bit VDR is not modelled");
		rows = s.nrows ? s.nrows : 16;
		words = s.rowlen ? s.rowlen : 16;
		const unsigned vpitch = s.vpitch ? s.vpitch : 16;
		const uint32_t pitch = s.mpitch ? 8u << s.mpitch : VdrStride::fromWord(vdr_pitch_).pitch;
		const unsigned y = s.addrxy >> 4, x = s.addrxy & 15;
		for (unsigned r = 0; r < rows; ++r)
			for (unsigned w = 0; w < words; ++w) {
				const uint32_t value = v3d_->memory_.read32(address + r * pitch + w * 4);
				if (!s.vertical)
					vpmAt(y + r * vpitch + (x + w) / 16, (x + w) % 16) = value;
				else
					vpmAt(y + w, x + r * vpitch) = value;
			}
	}
	(store ? stats_.traffic.vdw_written : stats_.traffic.vdr_read) += 4ull * rows * words;
	uint64_t &done = store ? vdw_done_ : vdr_done_;
	done = std::max(done, clock()) + t.dma_setup + rows * t.dma_per_row + rows * words * t.dma_per_word;
}

void Qpu::executeBranch(uint64_t word)
{
	const auto b = std::get<Branch>(decode(word));
	if (!branchTaken(static_cast<uint8_t>(b.cond)))
		return;
	const uint32_t link = pc_ + 32; // section 3 "Branches": PC + 4 instructions
	uint32_t target = static_cast<uint32_t>(b.offset);
	if (b.rel)
		target += link;
	if (b.reg)
		target += read(b.raddr_a, false)[15]; // addendum: element 15, not element 0
	write(b.waddr_add, b.ws, broadcast(link), kAll, false);
	write(b.waddr_mul, !b.ws, broadcast(link), kAll, false);
	// Addendum: bit 45 (sf) overlaps raddr_a bit 0; flags follow the link value.
	if (b.raddr_a & 1) {
		std::array<uint32_t, kLanes> v;
		v.fill(link);
		setFlags(v, {}, kAll, false);
	}
	// Counted down after every instruction including this one: three delay slots run.
	branches_.push_back({4, target});
}

void Qpu::executeLoad(uint64_t word)
{
	const Instr instr = decode(word);
	Vec value;
	const Writes *w;
	if (const auto *s = std::get_if<Semaphore>(&instr)) {
		// Section 3 "Semaphore Instruction": 16 four-bit counting semaphores.
		uint8_t &count = v3d_->semaphores_[s->number];
		if (s->down) {
			--count; // availability checked before execution
			if (v3d_->semaphore_release_cycle_[s->number] > clock()) {
				stats_.stall_cycles += v3d_->semaphore_release_cycle_[s->number] - clock();
				stats_.cycles = v3d_->semaphore_release_cycle_[s->number];
			}
		} else {
			if (count == 15 && v3d_->config_.strict)
				fault("semaphore " + std::to_string(s->number) + " incremented beyond 15");
			count = static_cast<uint8_t>((count + 1) & 15);
			v3d_->semaphore_release_cycle_[s->number] = clock();
		}
		value = broadcast(s->number | uint32_t{s->down} << 4 | s->ignored << 5);
		w = s;
	} else {
		const auto &l = std::get<LoadImm>(instr);
		switch (static_cast<LoadMode>(l.mode)) {
		case LoadMode::Word:
			value = broadcast(l.value);
			break;
		case LoadMode::PerElementSigned:
		case LoadMode::PerElementUnsigned:
			for (unsigned i = 0; i < kLanes; ++i) {
				uint32_t x = ((l.value >> i) & 1) | (((l.value >> (16 + i)) & 1) << 1);
				if (l.mode == static_cast<uint8_t>(LoadMode::PerElementSigned) && x >= 2)
					x |= 0xfffffffcu;
				value[i] = x;
			}
			break;
		default:
			fault("undocumented load-immediate mode " + std::to_string(l.mode));
		}
		w = &std::get<LoadImm>(instr);
	}
	const bool add_to_a = !w->ws;
	Mask add_mask, mul_mask;
	for (unsigned i = 0; i < kLanes; ++i) {
		add_mask[i] = cond(static_cast<uint8_t>(w->cond_add), i);
		mul_mask[i] = cond(static_cast<uint8_t>(w->cond_mul), i);
	}
	// pm = 0 packs the write that lands in physical regfile A.
	auto packed = [&](uint8_t waddr, bool file_a) {
		Vec out = value;
		if (w->pm || !file_a || waddr >= 32 || w->pack == Pack::None)
			return out;
		for (unsigned l = 0; l < kLanes; ++l)
			out[l] = packRegfileA(w->pack, {value[l], false, static_cast<int32_t>(value[l])}, false,
			                      ra_[waddr][l]);
		return out;
	};
	const bool add_cond = w->cond_add != Cond::Always;
	const bool mul_cond = w->cond_mul != Cond::Always;
	if (w->cond_add != Cond::Never)
		write(w->waddr_add, !add_to_a, packed(w->waddr_add, add_to_a), add_mask, add_cond);
	if (w->cond_mul != Cond::Never)
		write(w->waddr_mul, add_to_a, packed(w->waddr_mul, !add_to_a), mul_mask, mul_cond);
	if (w->sf) {
		Mask m;
		for (unsigned i = 0; i < kLanes; ++i)
			m[i] = w->cond_add == Cond::Never ? true : add_mask[i];
		std::array<uint32_t, kLanes> v;
		std::copy(value.begin(), value.end(), v.begin());
		setFlags(v, {}, m, false);
	}
}

void Qpu::executeAlu(uint64_t word)
{
	const auto i = std::get<Alu>(decode(word));
	switch (i.sig) {
	case Sig::Breakpoint: case Sig::None: case Sig::ProgramEnd: case Sig::LoadTmu0:
	case Sig::LoadTmu1: case Sig::SmallImmediate: case Sig::ThreadSwitch:
	case Sig::LastThreadSwitch:
		break;
	default:
		fault("signal " + std::to_string(static_cast<unsigned>(i.sig)) +
		      " is for fragment shaders (scoreboard/TLB)");
	}
	const bool add = i.op_add != AddOp::Nop;
	const bool mul = i.op_mul != MulOp::Nop;
	const bool smi = i.sig == Sig::SmallImmediate;

	// Read phase: raddr fields read their register or peripheral whether or not a mux uses it.
	Vec va = broadcast(0), vb = broadcast(0);
	auto uses = [&](Mux m) {
		return (add && (i.add_a == m || (!isUnary(i.op_add) && i.add_b == m))) ||
		       (mul && (i.mul_a == m || i.mul_b == m));
	};
	auto sideEffect = [](uint8_t r) {
		return r == raddr::uniform || r == raddr::vpm_read || r == raddr::vdr_wait ||
		       r == raddr::mutex_acquire;
	};
	if (uses(Mux::A) || sideEffect(i.raddr_a))
		va = read(i.raddr_a, false);
	if (smi)
		vb = broadcast(smallimm::value(i.raddr_b));
	else if (uses(Mux::B) || sideEffect(i.raddr_b))
		vb = read(i.raddr_b, true);

	if (v3d_->config_.strict && !sfu_pending_.empty() && uses(Mux::R4))
		fault("r4 read within 2 instructions of an SFU write");
	auto input = [&](Mux m, bool float_consumer) {
		Vec v = m == Mux::A ? va : m == Mux::B ? vb : acc_[static_cast<unsigned>(m)];
		if (!i.pm && m == Mux::A && i.unpack != Unpack::None)
			for (auto &x : v)
				x = unpackRegfileA(i.unpack, x, float_consumer);
		if (i.pm && m == Mux::R4 && i.unpack != Unpack::None)
			for (auto &x : v)
				x = unpackR4(i.unpack, x);
		return v;
	};

	std::array<LaneResult, kLanes> add_r{}, mul_r{};
	if (add) {
		const Vec a = input(i.add_a, isFloatOp(i.op_add));
		const Vec b = input(i.add_b, isFloatOp(i.op_add));
		for (unsigned l = 0; l < kLanes; ++l)
			add_r[l] = addOp(i.op_add, a[l], b[l]);
	}
	if (mul) {
		const Vec a = input(i.mul_a, isFloatOp(i.op_mul));
		const Vec b = input(i.mul_b, isFloatOp(i.op_mul));
		for (unsigned l = 0; l < kLanes; ++l)
			mul_r[l] = mulOp(i.op_mul, a[l], b[l]);
		if (smi && smallimm::isRotation(i.raddr_b)) {
			// Section 3 "Vector rotation": by 1..15 or by r5 element 0. With an input
			// outside r0..r3 only a rotation within each quad happens (addendum).
			const unsigned n = i.raddr_b == smallimm::rotate_by_r5 ? acc_[5][0] & 15 : i.raddr_b - 48u;
			const bool full = i.mul_a <= Mux::R3 && i.mul_b <= Mux::R3;
			auto src = mul_r;
			for (unsigned l = 0; l < kLanes; ++l)
				mul_r[l] = full ? src[(l - n) & 15] : src[(l & ~3u) | ((l - n) & 3)];
		}
	}

	// Write phase.
	Mask add_mask{}, mul_mask{};
	for (unsigned l = 0; l < kLanes; ++l) {
		add_mask[l] = cond(static_cast<uint8_t>(i.cond_add), l);
		mul_mask[l] = cond(static_cast<uint8_t>(i.cond_mul), l);
	}
	if (add && i.cond_add != Cond::Never) {
		const bool file_b = i.ws;
		Vec v;
		for (unsigned l = 0; l < kLanes; ++l) {
			v[l] = add_r[l].value;
			if (!i.pm && !file_b && i.waddr_add < 32 && i.pack != Pack::None)
				v[l] = packRegfileA(i.pack, add_r[l], hasFloatResult(i.op_add), ra_[i.waddr_add][l]);
		}
		write(i.waddr_add, file_b, v, add_mask, i.cond_add != Cond::Always);
	}
	if (mul && i.cond_mul != Cond::Never) {
		const bool file_b = !i.ws;
		Vec v;
		for (unsigned l = 0; l < kLanes; ++l) {
			v[l] = mul_r[l].value;
			const uint32_t old = i.waddr_mul < 32 ? (file_b ? rb_ : ra_)[i.waddr_mul][l]
			                     : i.waddr_mul <= waddr::r3 ? acc_[i.waddr_mul - 32][l] : 0;
			if (i.pm)
				v[l] = packMul(i.pack, mul_r[l].value, old);
			else if (!file_b && i.waddr_mul < 32 && i.pack != Pack::None)
				v[l] = packRegfileA(i.pack, mul_r[l], isFloatOp(i.op_mul), old);
		}
		write(i.waddr_mul, file_b, v, mul_mask, i.cond_mul != Cond::Always);
	}
	// Addendum: flags come from the ADD result unless the ADD op is nop, and only lanes
	// whose condition is true update; the "never" condition does not suppress them.
	if (i.sf && (add || mul)) {
		const bool from_add = add;
		const Cond c = from_add ? i.cond_add : i.cond_mul;
		std::array<uint32_t, kLanes> v;
		std::array<bool, kLanes> carry;
		Mask m;
		for (unsigned l = 0; l < kLanes; ++l) {
			const LaneResult &r = from_add ? add_r[l] : mul_r[l];
			v[l] = r.value;
			carry[l] = r.carry;
			m[l] = c == Cond::Never ? true : (from_add ? add_mask[l] : mul_mask[l]);
		}
		setFlags(v, carry, m, from_add ? hasFloatResult(i.op_add) : isFloatOp(i.op_mul));
	}
	if (i.sig == Sig::LoadTmu0 || i.sig == Sig::LoadTmu1) {
		auto &fifo = tmu_fifo_[i.sig == Sig::LoadTmu1];
		if (fifo.empty())
			fault("ldtmu with no TMU request outstanding");
		const TmuResult r = fifo.front();
		fifo.erase(fifo.begin());
		if (r.ready > clock()) {
			stats_.stall_cycles += r.ready - clock();
			stats_.cycles = r.ready;
		}
		acc_[4] = r.value;
	}
	if (i.sig == Sig::ProgramEnd) {
		if (end_slots_ >= 0)
			fault("second program end in the delay slots of the first");
		end_slots_ = 2;
	}
}

void Qpu::advance()
{
	written_a_ = writing_a_;
	written_b_ = writing_b_;
	writing_a_ = writing_b_ = 0;
	if (unif_addr_slots_ > 0)
		--unif_addr_slots_;
	// An SFU result lands at the end of the second instruction after its write (4 -> 1).
	for (auto &p : sfu_pending_)
		if (--p.slots == 1)
			acc_[4] = p.value;
	std::erase_if(sfu_pending_, [](const SfuResult &p) { return p.slots <= 1; });
}

Qpu::Step Qpu::step()
{
	if (halted_)
		return Step::Halted;
	uint64_t word;
	try {
		word = v3d_->memory_.read64(pc_);
	} catch (const MemoryError &e) {
		fault(std::string("instruction fetch: ") + e.what());
	}
	const auto sig = static_cast<Sig>(field::sig.get(word));
	// Blocking checks happen before any side effect so the instruction can be retried.
	if (sig == Sig::LoadImmediate && field::ldi_mode.get(word) == 4 && field::sema_down.get(word) &&
	    v3d_->semaphores_[field::sema_number.get(word)] == 0)
		return Step::Blocked;
	if (sig < Sig::LoadImmediate) {
		const auto ra = static_cast<uint8_t>(field::raddr_a.get(word));
		const auto rb = static_cast<uint8_t>(field::raddr_b.get(word));
		if (wouldBlock(ra, false) || (sig != Sig::SmallImmediate && wouldBlock(rb, true)))
			return Step::Blocked;
	}
	stats_.cycles += v3d_->config_.timing.cycles_per_instruction;
	++stats_.instructions;
	try {
		if (sig == Sig::Branch)
			executeBranch(word);
		else if (sig == Sig::LoadImmediate)
			executeLoad(word);
		else
			executeAlu(word);
	} catch (const MemoryError &e) {
		fault(e.what());
	}
	advance();

	pc_ += 8;
	for (auto &b : branches_)
		if (--b.slots == 0)
			pc_ = b.target;
	std::erase_if(branches_, [](const PendingBranch &b) { return b.slots == 0; });
	if (end_slots_ >= 0 && end_slots_-- == 0)
		halted_ = true;
	return halted_ ? Step::Halted : Step::Executed;
}

} // namespace frappe::vc4::emu
