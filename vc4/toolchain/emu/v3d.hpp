// SPDX-License-Identifier: MIT
// Emulator of the V3D's 12 QPUs with their shared peripherals (VPM, VCD DMA, TMUs,
// semaphores, mutex, host interrupt) and a scheduler with a launch interface shaped like
// the mailbox execute_qpu call (one (uniforms, code) pair per QPU).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "emu/memory.hpp"
#include "tmu_depth.hpp"

namespace frappe::vc4::emu {

inline constexpr unsigned kLanes = 16;
inline constexpr unsigned kQpus = 12;
using Vec = std::array<uint32_t, kLanes>;

// A program did something the hardware documents as undefined, or deadlocked.
class Fault : public std::runtime_error {
public:
	Fault(int qpu, uint32_t pc, const std::string &what);
	int qpu;
	uint32_t pc;
};

// Issue model (reference guide section 3: one instruction per 4 clocks per QPU) and the
// stall parameters that only hardware measurements can calibrate.
struct Timing {
	unsigned cycles_per_instruction = 4;
	unsigned tmu_latency = 40;     // cycles from TMU request to data ready
	unsigned dma_setup = 20;       // cycles before a VDR/VDW transfers its first row
	unsigned dma_per_row = 4;
	unsigned dma_per_word = 1;
};

struct Config {
	Timing timing;
	unsigned bilinear_fraction_bits = 8; // TMU bilinear weight precision (not documented)
	unsigned vpm_rows = 192;             // 12 KiB, 16 words per row
	// Outstanding TMU requests per QPU, both TMUs together, that strict mode allows: the
	// build's depth (tmu_depth.hpp). Lenient mode only keeps each TMU's FIFO to its 8 slots.
	unsigned tmu_fifo_limit = kTmuDepth;
	bool strict = true;                  // turn documented hazards into faults
	uint64_t max_instructions = 100'000'000;
};

// One QPU's work: the same pair the mailbox execute_qpu message carries.
struct Job {
	uint32_t uniforms = 0;
	uint32_t code = 0;
};

enum class Schedule { RoundRobin, Random };

struct LaunchOptions {
	Schedule schedule = Schedule::RoundRobin;
	uint64_t seed = 0;
};

// Memory traffic, in bytes: what the QPU's requests move between memory and the QPU or
// VPM (a general TMU gather counts 64 bytes, 4 a lane; caches are not modelled).
struct Traffic {
	uint64_t tmu_read = 0;     // TMU gathers and texture fetches
	uint64_t vdr_read = 0;     // VPM DMA loads
	uint64_t vdw_written = 0;  // VPM DMA stores
	uint64_t uniform_read = 0; // the uniform stream

	uint64_t read() const { return tmu_read + vdr_read + uniform_read; }
	Traffic &operator+=(const Traffic &o)
	{
		tmu_read += o.tmu_read;
		vdr_read += o.vdr_read;
		vdw_written += o.vdw_written;
		uniform_read += o.uniform_read;
		return *this;
	}
};

struct QpuStats {
	uint64_t instructions = 0;
	uint64_t cycles = 0;
	uint64_t stall_cycles = 0;
	unsigned host_interrupts = 0;
	Traffic traffic;
};

struct LaunchStats {
	std::vector<QpuStats> qpus;
	uint64_t instructions = 0; // all QPUs
	uint64_t cycles = 0;       // the slowest QPU
	unsigned host_interrupts = 0;
	Traffic traffic;           // all QPUs
};

class Qpu;

class V3d {
public:
	explicit V3d(Memory &memory, Config config = {});
	~V3d();
	V3d(const V3d &) = delete;
	V3d &operator=(const V3d &) = delete;

	// Runs jobs[i] on QPU i until every QPU reaches program end.
	LaunchStats launch(std::span<const Job> jobs, LaunchOptions options = {});

	Memory &memory() { return memory_; }
	const Config &config() const { return config_; }
	uint32_t &vpm(unsigned row, unsigned column);
	uint8_t semaphore(unsigned n) const { return semaphores_.at(n); }
	// State of QPU `n` after a launch (registers, flags) for tests.
	const Qpu &qpu(unsigned n) const;

private:
	friend class Qpu;

	Memory &memory_;
	Config config_;
	std::vector<uint32_t> vpm_;
	std::array<uint8_t, 16> semaphores_{};
	std::array<uint64_t, 16> semaphore_release_cycle_{};
	int mutex_owner_ = -1;
	uint64_t mutex_release_cycle_ = 0;
	std::vector<std::unique_ptr<Qpu>> qpus_;
};

// Architectural state of one QPU, readable for tests.
class Qpu {
public:
	Qpu(V3d &v3d, unsigned id);

	enum class Step { Executed, Blocked, Halted };
	void start(const Job &job);
	Step step();

	unsigned id() const { return id_; }
	bool halted() const { return halted_; }
	const Vec &regA(unsigned n) const { return ra_.at(n); }
	const Vec &regB(unsigned n) const { return rb_.at(n); }
	const Vec &acc(unsigned n) const { return acc_.at(n); }
	bool flagZ(unsigned lane) const { return z_[lane]; }
	bool flagN(unsigned lane) const { return n_[lane]; }
	bool flagC(unsigned lane) const { return c_[lane]; }
	uint32_t pc() const { return pc_; }
	const QpuStats &stats() const { return stats_; }
	uint64_t clock() const { return stats_.cycles; }

private:
	struct TmuRequest {
		bool coords_written = false; // T, R or B written: a texture lookup
		Vec t{}, r{}, b{};
	};
	struct TmuResult {
		Vec value;
		uint64_t ready;
	};

	[[noreturn]] void fault(const std::string &what) const;
	bool cond(uint8_t code, unsigned lane) const;
	bool branchTaken(uint8_t code) const;
	bool wouldBlock(uint8_t raddr, bool file_b) const;
	Vec read(uint8_t raddr, bool file_b);
	void write(uint8_t waddr, bool file_b, const Vec &value, const std::array<bool, kLanes> &mask,
	           bool conditional);
	void setFlags(const std::array<uint32_t, kLanes> &value, const std::array<bool, kLanes> &carry,
	              const std::array<bool, kLanes> &mask, bool float_op);
	void executeAlu(uint64_t word);
	void executeLoad(uint64_t word);
	void executeBranch(uint64_t word);
	void vpmWrite(const Vec &v);
	Vec vpmRead();
	void vpmSetup(bool write, uint32_t word);
	void dmaStart(bool store, uint32_t address);
	void tmuWrite(unsigned tmu, unsigned reg, const Vec &v);
	uint32_t popUniform();
	void advance();

	V3d *v3d_;
	unsigned id_;
	bool halted_ = true;
	uint32_t pc_ = 0;
	uint32_t uniforms_ = 0;
	std::array<Vec, 32> ra_{}, rb_{};
	std::array<Vec, 6> acc_{};
	std::array<bool, kLanes> z_{}, n_{}, c_{};

	// Delayed effects.
	struct PendingBranch {
		int slots;
		uint32_t target;
	};
	std::vector<PendingBranch> branches_;
	int end_slots_ = -1;
	struct SfuResult {
		int slots;
		Vec value;
	};
	std::vector<SfuResult> sfu_pending_;
	int unif_addr_slots_ = 0;
	uint32_t written_a_ = 0, written_b_ = 0, writing_a_ = 0, writing_b_ = 0;

	std::array<TmuRequest, 2> tmu_request_{};
	std::array<std::vector<TmuResult>, 2> tmu_fifo_{};
	bool tmu_noswap_ = false;

	// VPM generic block access (section 7 "VPM generic block read/write").
	uint32_t vpm_write_setup_ = 0;
	unsigned vpm_write_addr_ = 0;
	uint32_t vpm_read_setup_ = 0;
	unsigned vpm_read_addr_ = 0;
	unsigned vpm_read_left_ = 0;
	std::vector<Vec> vpm_read_fifo_;

	// VCD DMA (section 7 "VCD DMA").
	uint32_t vdr_setup_ = 0, vdr_pitch_ = 0, vdw_setup_ = 0, vdw_stride_ = 0;
	uint64_t vdr_done_ = 0, vdw_done_ = 0;

	QpuStats stats_;
};

} // namespace frappe::vc4::emu
