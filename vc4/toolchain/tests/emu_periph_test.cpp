// SPDX-License-Identifier: MIT
// Peripherals of the emulated V3D, one test per setup form and mode: VPM generic block
// read/write (reference guide section 7, Tables 32/33), VDR (Tables 36/37) and VDW
// (Tables 34/35, 16-bit stride per the vc4asm addendum), TMU direct lookups (section 4),
// semaphores and the mutex (section 3), branch forms (section 3 "Branches" + addendum).
#include <gtest/gtest.h>

#include "emu/device.hpp"
#include "harness.hpp"
#include "isa/setup_words.hpp"

using namespace frappe::vc4;
using namespace frappe::vc4::qasm;
using frappe::vc4::test::run;
using isa::BranchCond;
using isa::Sig;

namespace {
void writeVector(Assembler &a, uint32_t setup)
{
	a.ldi(reg::vw_setup, setup);
	a.emit(add(reg::vpm_write, reg::elem_num, imm(1)));
}
} // namespace

TEST(EmuVpm, GenericHorizontal32WithStride)
{
	Assembler a;
	a.ldi(reg::vw_setup, isa::VpmWriteSetup{.stride = 2, .horizontal = true, .laned = false,
	                                         .size = isa::VpmSize::Bits32, .addr = 5}.word());
	a.emit(add(reg::vpm_write, reg::elem_num, imm(1)));
	a.emit(add(reg::vpm_write, reg::elem_num, imm(2)));
	a.ldi(reg::vr_setup, isa::VpmReadSetup{.num = 2, .stride = 2, .horizontal = true, .laned = false,
	                                        .size = isa::VpmSize::Bits32, .addr = 5}.word());
	a.emit(mov(r0, reg::vpm));
	a.emit(mov(r1, reg::vpm));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->v3d.vpm(5, i), i + 1);
		EXPECT_EQ(r->v3d.vpm(7, i), i + 2); // stride 2 rows
		EXPECT_EQ(r->qpu().acc(0)[i], i + 1);
		EXPECT_EQ(r->qpu().acc(1)[i], i + 2);
	}
}

TEST(EmuVpm, GenericVertical32)
{
	Assembler a;
	writeVector(a, isa::VpmWriteSetup{.stride = 1, .horizontal = false, .laned = false,
	                                  .size = isa::VpmSize::Bits32, .addr = (1 << 4) | 3}.word());
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i)
		EXPECT_EQ(r->v3d.vpm(16 + i, 3), i + 1);
}

TEST(EmuVpm, GenericHorizontal8And16BitLanes)
{
	Assembler a;
	// 8-bit: ADDR = row * 4 + byte; element e goes to byte lane 2 of word e.
	writeVector(a, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = true,
	                                  .size = isa::VpmSize::Bits8, .addr = 3 * 4 + 2}.word());
	// 16-bit: ADDR = row * 2 + half.
	writeVector(a, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = true,
	                                  .size = isa::VpmSize::Bits16, .addr = 4 * 2 + 1}.word());
	a.ldi(reg::vr_setup, isa::VpmReadSetup{.num = 1, .stride = 1, .horizontal = true, .laned = true,
	                                        .size = isa::VpmSize::Bits8, .addr = 3 * 4 + 2}.word());
	a.emit(mov(r0, reg::vpm));
	a.thrend();
	auto r = run(a.finish());
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->v3d.vpm(3, i), (i + 1) << 16);
		EXPECT_EQ(r->v3d.vpm(4, i), (i + 1) << 16);
		EXPECT_EQ(r->qpu().acc(0)[i], i + 1);
	}
}

namespace {
// Runs `program` with memory words at the address given as its first uniform.
std::unique_ptr<test::Run> runWithBuffer(const Program &p, std::vector<uint32_t> buffer,
                                         uint32_t *address)
{
	auto r = std::make_unique<test::Run>();
	*address = r->memory.load(buffer);
	const uint32_t code = r->memory.load(p.code);
	const emu::Job job{r->memory.load(std::vector<uint32_t>{*address}), code};
	r->stats = r->v3d.launch(std::span(&job, 1));
	return r;
}
std::vector<uint32_t> counting(uint32_t n)
{
	std::vector<uint32_t> v(n);
	for (uint32_t i = 0; i < n; ++i)
		v[i] = 1000 + i;
	return v;
}
} // namespace

TEST(EmuVcd, VdrHorizontalWithPowerOfTwoPitch)
{
	// MPITCH 3: rows 8 * 2^3 = 64 bytes apart; 3 rows of 4 words to VPM (Y 2, X 1), VPITCH 2.
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.ldi(reg::vr_setup, isa::VdrSetup{.modew = 0, .mpitch = 3, .rowlen = 4, .nrows = 3, .vpitch = 2,
	                                    .vertical = false, .addrxy = (2 << 4) | 1}.word());
	a.emit(mov(reg::vr_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vr_wait));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), counting(64), &address);
	for (unsigned row = 0; row < 3; ++row)
		for (unsigned w = 0; w < 4; ++w)
			EXPECT_EQ(r->v3d.vpm(2 + 2 * row, 1 + w), 1000 + row * 16 + w);
	EXPECT_EQ(r->v3d.vpm(3, 1), 0u);
}

TEST(EmuVcd, VdrVerticalWithExtendedPitch)
{
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.ldi(reg::vr_setup, isa::VdrStride{.pitch = 40}.word());
	a.ldi(reg::vr_setup, isa::VdrSetup{.modew = 0, .mpitch = 0, .rowlen = 4, .nrows = 2, .vpitch = 1,
	                                    .vertical = true, .addrxy = (8 << 4) | 5}.word());
	a.emit(mov(reg::vr_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vr_wait));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), counting(64), &address);
	for (unsigned row = 0; row < 2; ++row)
		for (unsigned w = 0; w < 4; ++w)
			EXPECT_EQ(r->v3d.vpm(8 + w, 5 + row), 1000 + row * 10 + w);
}

TEST(EmuVcd, VdwHorizontalWithStride)
{
	// 2 rows of 3 words from VPM (Y 4, X 2); 8 bytes skipped after each row in memory.
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.ldi(reg::vw_setup, isa::VpmWriteSetup{.stride = 1, .horizontal = true, .laned = false,
	                                         .size = isa::VpmSize::Bits32, .addr = 4}.word());
	a.emit(add(reg::vpm_write, reg::elem_num, imm(10)));
	a.emit(add(reg::vpm_write, reg::elem_num, imm(15)));
	a.ldi(reg::vw_setup, isa::VdwStride{.stride = 8}.word());
	a.ldi(reg::vw_setup, isa::VdwSetup{.units = 2, .depth = 3, .horizontal = true,
	                                    .vpm_base = isa::VdwSetup::base32(4, 2), .modew = 0}.word());
	a.emit(mov(reg::vw_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), std::vector<uint32_t>(16, 7), &address);
	const uint32_t expect[] = {12, 13, 14, 7, 7, 17, 18, 19, 7};
	for (unsigned i = 0; i < 9; ++i)
		EXPECT_EQ(r->memory.read32(address + 4 * i), expect[i]) << i;
}

TEST(EmuVcd, VdwVertical)
{
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.ldi(reg::vw_setup, isa::VpmWriteSetup{.stride = 1, .horizontal = false, .laned = false,
	                                         .size = isa::VpmSize::Bits32, .addr = 0}.word());
	a.emit(add(reg::vpm_write, reg::elem_num, imm(1)));       // column 0, rows 0..15
	a.ldi(reg::vw_setup, isa::VdwSetup{.units = 1, .depth = 4, .horizontal = false,
	                                    .vpm_base = isa::VdwSetup::base32(2, 0), .modew = 0}.word());
	a.emit(mov(reg::vw_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vw_wait));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), std::vector<uint32_t>(8, 0), &address);
	for (unsigned i = 0; i < 4; ++i)
		EXPECT_EQ(r->memory.read32(address + 4 * i), 3 + i);
}

TEST(EmuVcd, WaitStallsUntilModelledCompletion)
{
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.ldi(reg::vr_setup, isa::VdrSetup{.modew = 0, .mpitch = 3, .rowlen = 0, .nrows = 0, .vpitch = 1,
	                                    .vertical = false, .addrxy = 0}.word());
	a.emit(mov(reg::vr_addr, ra(0)));
	a.emit(mov(reg::nop, reg::vr_wait));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), counting(256), &address);
	const emu::Timing t;
	// Issued at cycle 12 (third instruction); 16 rows of 16 words.
	const uint64_t done = 12 + t.dma_setup + 16 * t.dma_per_row + 256 * t.dma_per_word;
	EXPECT_EQ(r->stats.qpus[0].stall_cycles, done - 16);
	EXPECT_EQ(r->stats.cycles, done + 3 * 4);
}

TEST(EmuTmu, DirectLookupsComeBackInOrder)
{
	Assembler a;
	a.emit(mov(wa(0), a.uniform("buf")));
	a.emit(shl(r1, reg::elem_num, imm(2)));
	a.emit(add(reg::tmu0_s, ra(0), r1));
	a.emit(add(r2, r1, imm(8)));
	a.emit(add(reg::tmu0_s, ra(0), r2));
	a.ldtmu(0);
	a.emit(mov(r0, r4));
	a.ldtmu(0);
	a.emit(mov(r3, r4));
	a.thrend();
	uint32_t address;
	auto r = runWithBuffer(a.finish(), counting(64), &address);
	for (unsigned i = 0; i < 16; ++i) {
		EXPECT_EQ(r->qpu().acc(0)[i], 1000 + i);
		EXPECT_EQ(r->qpu().acc(3)[i], 1002 + i);
	}
	// First request retires at cycle 12 and is ready at 12 + 40; its ldtmu issues at 24.
	EXPECT_EQ(r->stats.qpus[0].stall_cycles, 12 + emu::Timing{}.tmu_latency - 24);
}

TEST(EmuTmu, OutstandingRequestLimit)
{
	// Strict mode holds a QPU to the configured depth, both TMUs together (the build's
	// kTmuDepth by default); lenient mode only to each TMU's 8 FIFO slots (section 4).
	auto program = [](int tmu0, int tmu1) {
		Assembler a;
		a.emit(mov(wa(0), a.uniform("buf")));
		a.nop();
		for (int i = 0; i < tmu0 + tmu1; ++i)
			a.emit(mov(i < tmu0 ? reg::tmu0_s : reg::tmu1_s, ra(0)));
		a.thrend();
		return a.finish(false); // the lint would reject these already
	};
	auto launch = [](const Program &p, emu::Config c) {
		test::Run r(c);
		const uint32_t buf = r.memory.load(counting(16));
		const uint32_t code = r.memory.load(p.code);
		const emu::Job job{r.memory.load(std::vector<uint32_t>{buf}), code};
		return r.v3d.launch(std::span(&job, 1));
	};
	EXPECT_EQ(emu::Config{}.tmu_fifo_limit, kTmuDepth);
	emu::Config four, eight, lenient;
	four.tmu_fifo_limit = 4;
	eight.tmu_fifo_limit = 8;
	lenient.strict = false;
	EXPECT_NO_THROW(launch(program(4, 0), four));
	EXPECT_NO_THROW(launch(program(2, 2), four));
	EXPECT_THROW(launch(program(5, 0), four), emu::Fault);
	EXPECT_THROW(launch(program(3, 2), four), emu::Fault); // per QPU, not per TMU
	EXPECT_NO_THROW(launch(program(3, 2), eight));
	EXPECT_NO_THROW(launch(program(4, 4), eight));
	EXPECT_THROW(launch(program(5, 4), eight), emu::Fault);
	EXPECT_NO_THROW(launch(program(8, 8), lenient));
	EXPECT_THROW(launch(program(9, 0), lenient), emu::Fault);
	// Each general gather reads 16 words; the program read one uniform.
	const emu::LaunchStats s = launch(program(2, 1), four);
	EXPECT_EQ(s.traffic.tmu_read, 3u * 64u);
	EXPECT_EQ(s.traffic.uniform_read, 4u);
	EXPECT_EQ(s.traffic.vdw_written, 0u);
}

TEST(EmuTmu, LdtmuWithoutRequestFaults)
{
	Assembler a;
	a.ldtmu(1);
	a.thrend();
	EXPECT_THROW(run(a.finish(false)), emu::Fault);
}

TEST(EmuSync, SemaphoreCountsAndOverflowFaults)
{
	Assembler a;
	for (int i = 0; i < 3; ++i)
		a.semaphoreRelease(4);
	a.semaphoreAcquire(4);
	a.thrend();
	EXPECT_EQ(run(a.finish())->v3d.semaphore(4), 2u);
	Assembler b;
	for (int i = 0; i < 16; ++i)
		b.semaphoreRelease(1);
	b.thrend();
	EXPECT_THROW(run(b.finish()), emu::Fault);
}

TEST(EmuSync, MutexSerialisesQpus)
{
	Assembler a;
	a.emit(mov(reg::nop, reg::mutex_acq));
	for (int i = 0; i < 10; ++i)
		a.nop();
	a.emit(mov(reg::mutex_rel, imm(1)));
	a.thrend();
	auto r = run(a.finish(), {{}}, 2);
	const auto &q0 = r->stats.qpus[0], &q1 = r->stats.qpus[1];
	EXPECT_EQ(q0.instructions, q1.instructions);
	EXPECT_EQ(q0.stall_cycles, 0u);
	// QPU 1 acquires at QPU 0's release (cycle 48) instead of cycle 4.
	EXPECT_EQ(q1.stall_cycles, 48u - 4u);
	EXPECT_EQ(q1.cycles, q0.cycles + 44u);
}

TEST(EmuSync, ReleasingAMutexNotHeldFaults)
{
	Assembler a;
	a.emit(mov(reg::mutex_rel, imm(1)));
	a.thrend();
	EXPECT_THROW(run(a.finish()), emu::Fault);
}

TEST(EmuBranch, LinkWrittenOnlyWhenTaken)
{
	// Addendum "Branch Instruction - target assignment".
	Assembler a;
	Label l = a.newLabel();
	a.ldi(wa(5), 77);
	a.emit(mov(reg::nop, imm(1)).setFlags()); // Z clear everywhere
	a.branch(l, BranchCond::AllZSet, wa(5));
	a.nop(); a.nop(); a.nop();
	a.bind(l);
	a.thrend();
	EXPECT_EQ(run(a.finish())->qpu().regA(5)[0], 77u);
}

TEST(EmuBranch, AbsoluteRegisterBranch)
{
	Assembler a;
	a.emit(mov(wa(2), a.uniform("target")));
	a.nop();
	a.branchRegister(2, 0);
	a.nop(); a.nop(); a.nop();
	a.emit(mov(r0, imm(9))); // skipped: target is the instruction after it
	a.emit(add(r0, r0, imm(1)));
	a.thrend();
	test::Run r;
	const uint32_t code = r.memory.load(a.finish().code);
	const emu::Job job{r.memory.load(std::vector<uint32_t>{code + 7 * 8}), code};
	r.v3d.launch(std::span(&job, 1));
	EXPECT_EQ(r.qpu().acc(0)[0], 1u);
}

TEST(EmuBranch, OddRegisterSetsFlags)
{
	// Addendum "implicit set flags": raddr_a bit 0 overlaps sf.
	Assembler a;
	a.emit(mov(wa(1), imm(0)));
	a.emit(mov(reg::nop, imm(0)).setFlags()); // Z set everywhere
	a.branchRegister(1, 0, BranchCond::Always, reg::nop, true);
	a.nop(); a.nop(); a.nop();
	a.thrend();
	auto r = run(a.finish(false));
	EXPECT_FALSE(r->qpu().flagZ(0));
}

TEST(EmuTiming, FourCyclesPerInstructionWithoutStalls)
{
	Assembler a;
	for (int i = 0; i < 9; ++i)
		a.emit(add(r0, r0, imm(1)));
	a.thrend();
	auto r = run(a.finish(), {{}}, 3);
	for (const auto &q : r->stats.qpus) {
		EXPECT_EQ(q.instructions, 12u);
		EXPECT_EQ(q.cycles, 48u);
	}
	EXPECT_EQ(r->stats.instructions, 36u);
	EXPECT_EQ(r->stats.cycles, 48u);
}

TEST(EmuSfu, BackToBackWritesLandInOrder)
{
	Assembler a;
	a.emit(mov(reg::sfu_recip, imm(2.0f)));
	a.emit(mov(reg::sfu_recip, imm(4.0f)));
	a.nop();
	a.emit(mov(r0, r4));
	a.emit(mov(r1, r4));
	a.thrend();
	// Reading the first result inside the second one's window is a documented hazard.
	emu::Config lenient;
	lenient.strict = false;
	auto r = run(a.finish(false), {{}}, 1, lenient);
	EXPECT_EQ(r->qpu().acc(0)[0], 0x3f000000u); // 0.5
	EXPECT_EQ(r->qpu().acc(1)[0], 0x3e800000u); // 0.25
}

TEST(EmuSync, ConditionalSetupWriteUsesElementZero)
{
	// vr_setup/host_int take element 0: a condition false in lane 0 suppresses the write.
	Assembler a;
	a.emit(mov(reg::nop, reg::elem_num).setFlags()); // Z only in lane 0
	a.emit(mov(reg::host_int, imm(1)).ifnz());
	a.emit(mov(reg::host_int, imm(1)).ifz());
	a.thrend();
	EXPECT_EQ(run(a.finish(false))->stats.host_interrupts, 1u);
}

// Memory beyond the arena: allocations too large for it get releasable regions of their
// own; host memory (an mmapped dma-buf) is mapped in place, read-only when asked.
TEST(EmuMemory, RegionsAndExternalMappings)
{
	emu::Memory m(64u << 10);
	const uint32_t small = m.alloc(16u << 10);
	EXPECT_GE(small, m.base());
	EXPECT_LT(small, m.base() + m.size());
	const uint32_t big = m.alloc(1u << 20, 65536);
	EXPECT_GE(big, m.base() + m.size());
	EXPECT_EQ(big % 65536, 0u);
	EXPECT_EQ(m.read32(big + (1u << 20) - 4), 0u);
	m.write32(big + 8, 0xdeadbeef);
	EXPECT_EQ(m.read32(big + 8), 0xdeadbeefu);
	EXPECT_THROW(m.read32(big + (1u << 20)), emu::MemoryError); // one past the region
	EXPECT_EQ(m.regions(), 1u);

	std::vector<uint8_t> host(8192, 7);
	const uint32_t ext = m.mapExternal(host, false);
	EXPECT_NE(ext, big);
	EXPECT_EQ(m.read32(ext), 0x07070707u);
	host[4] = 1; // in place: the host's writes are what the QPUs read
	EXPECT_EQ(m.read32(ext + 4), 0x07070701u);
	EXPECT_THROW(m.write32(ext, 0), emu::MemoryError);
	EXPECT_THROW(m.read32(ext + 8192), emu::MemoryError);
	EXPECT_EQ(m.read32(big + 8), 0xdeadbeefu); // the other region still found
	std::vector<uint8_t> fixed(4096, 9);
	EXPECT_EQ(m.mapExternal(fixed, true, 0xDF000000u), 0xDF000000u); // where a fake GPU put it
	m.write32(0xDF000ffc, 0x05060708);
	EXPECT_EQ(fixed[4095], 5);
	EXPECT_THROW(m.mapExternal(fixed, true, 0xDF000800u), emu::MemoryError); // overlaps
	EXPECT_THROW(m.mapExternal(fixed, true, m.base()), emu::MemoryError);     // the arena
	m.release(0xDF000000u);

	emu::Device d(emu::Config{}, 64u << 10);
	std::vector<uint8_t> frame(4096, 3);
	const auto b = d.importExternal(frame, true);
	d.v3d().memory().write32(b.bus, 0x01020304);
	EXPECT_EQ(frame[0], 4);
	d.release(b);
	EXPECT_THROW(d.v3d().memory().read32(b.bus), emu::MemoryError);

	m.release(big);
	m.release(ext);
	m.release(small); // arena allocations stay: a no-op
	EXPECT_EQ(m.regions(), 0u);
	EXPECT_THROW(m.read32(big), emu::MemoryError);
	EXPECT_THROW(m.release(ext), emu::MemoryError);
}
