// SPDX-License-Identifier: MIT
// The real-GPU runtime against a fake kernel: ioctl numbers and struct layouts, mailbox
// property messages word for word, the probe's reasons, the memory fallback chain
// (dma-heap + vcsm-cma -> mailbox memory -> unavailable), cache syncs around launches,
// the execute_qpu control block, the timeout path and clean-up.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <optional>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <linux/dma-buf.h>
#include <linux/dma-heap.h>

#include "runtime/gpu_device.hpp"
#include "runtime/mailbox.hpp"
#include "runtime/os.hpp"
#include "runtime/uapi.hpp"
#include "runtime_fake_os.hpp"

using namespace frappe::vc4::runtime;
using test::FakeOs;
using Words = std::vector<uint32_t>;

namespace {

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

} // namespace

TEST(RuntimeUapi, IoctlNumbersMatchTheSystemHeaders)
{
	EXPECT_EQ(uapi::kIoctlDmaHeapAlloc, static_cast<unsigned long>(DMA_HEAP_IOCTL_ALLOC));
	EXPECT_EQ(uapi::kIoctlDmaBufSync, static_cast<unsigned long>(DMA_BUF_IOCTL_SYNC));
	EXPECT_EQ(sizeof(uapi::DmaHeapAllocationData), sizeof(dma_heap_allocation_data));
	EXPECT_EQ(sizeof(uapi::DmaBufSync), sizeof(dma_buf_sync));
	EXPECT_EQ(uapi::kDmaBufSyncEnd | uapi::kDmaBufSyncRw, uint64_t{DMA_BUF_SYNC_END | DMA_BUF_SYNC_RW});
	EXPECT_EQ(uapi::kDmaBufSyncStart | uapi::kDmaBufSyncRw, uint64_t{DMA_BUF_SYNC_START | DMA_BUF_SYNC_RW});
}

TEST(RuntimeUapi, PinnedNumbers)
{
	// vcio: _IOWR(100, 0, char *) for this process's pointer size.
	EXPECT_EQ(uapi::kIoctlMboxProperty, sizeof(void *) == 8 ? 0xC0086400ul : 0xC0046400ul);
	EXPECT_EQ(uapi::mboxPropertyIoctl(4), 0xC0046400u);
	// vc_sm_cma: _IOR('J', 0x5B, 64-byte struct).
	EXPECT_EQ(uapi::kIoctlVcsmImportDmabuf, 0x80404A5Bul);
	EXPECT_EQ(sizeof(uapi::VcsmImportDmabuf), 64u);
	EXPECT_EQ(offsetof(uapi::VcsmImportDmabuf, dma_addr), 56u);
}

TEST(RuntimeMailbox, MessagesWordForWord)
{
	const Words enable = {1};
	EXPECT_EQ(propertyMessage(0x00030012, enable, 1), (Words{28, 0, 0x00030012, 4, 0, 1, 0}));
	const Words exec = {12, 0xDE001000, 0, 500};
	EXPECT_EQ(propertyMessage(0x00030011, exec, 1),
	          (Words{40, 0, 0x00030011, 16, 0, 12, 0xDE001000, 0, 500, 0}));
	const Words clock = {5};
	EXPECT_EQ(propertyMessage(0x00030002, clock, 2), (Words{32, 0, 0x00030002, 8, 0, 5, 0, 0}));
	const Words alloc = {8192, 4096, 0xC};
	EXPECT_EQ(propertyMessage(0x0003000c, alloc, 1), (Words{36, 0, 0x0003000c, 12, 0, 8192, 4096, 0xC, 0}));
	EXPECT_EQ(propertyMessage(0x00000001, {}, 1), (Words{28, 0, 0x00000001, 4, 0, 0, 0}));
	// Little-endian bytes on the wire (ARM and x86 alike).
	const Words m = propertyMessage(0x00030012, enable, 1);
	const auto *b = reinterpret_cast<const uint8_t *>(m.data());
	EXPECT_EQ((std::vector<uint8_t>(b, b + 12)),
	          (std::vector<uint8_t>{28, 0, 0, 0, 0, 0, 0, 0, 0x12, 0x00, 0x03, 0x00}));
}

TEST(RuntimeMailbox, ResponsesAreChecked)
{
	EXPECT_EQ(propertyResponse(Words{32, 0x80000000, 0x30002, 8, 0x80000008, 5, 300000000, 0}, 2),
	          (Words{5, 300000000}));
	try {
		propertyResponse(Words{28, 0x80000001, 0x30012, 4, 0, 1, 0}, 1);
		FAIL();
	} catch (const RuntimeError &e) {
		EXPECT_STREQ(e.what(), "mailbox tag 0x00030012: the firmware could not parse the request (0x80000001)");
	}
	try {
		propertyResponse(Words{28, 0x80000000, 0x30012, 4, 0, 1, 0}, 1);
		FAIL();
	} catch (const RuntimeError &e) {
		EXPECT_STREQ(e.what(), "mailbox tag 0x00030012: the firmware does not know this tag (no response bit)");
	}
	EXPECT_THROW(propertyResponse(Words{28, 0, 0x30012, 4, 0, 1, 0}, 1), RuntimeError);
	EXPECT_THROW(propertyResponse(Words{32, 0x80000000, 0x30002, 8, 0x80000004, 5, 0, 0}, 2), RuntimeError);
}

TEST(RuntimeProbe, NotAPi)
{
	FakeOs os;
	const auto r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_EQ(r.reason, "not a Raspberry Pi: /proc/device-tree/model is missing");
	os.files["/proc/device-tree/model"] = std::string("Pine64 Rock64") + '\0';
	EXPECT_EQ(GpuDevice::probe(os).reason, "not a Raspberry Pi: the devicetree model is \"Pine64 Rock64\"");
	EXPECT_TRUE(os.messages.empty());
}

TEST(RuntimeProbe, Pi4HasNoVideoCoreIv)
{
	FakeOs os;
	os.pi("Raspberry Pi 4 Model B Rev 1.4", "bcm2711");
	const auto r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_TRUE(contains(r.reason, "VideoCore VI/VII GPU (bcm2711)")) << r.reason;
}

TEST(RuntimeProbe, KmsDriverBoundToV3d)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	os.dirs["/sys/bus/platform/drivers/vc4_v3d"] = {"bind", "20c00000.v3d", "uevent"};
	const auto r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_EQ(r.reason.rfind("the vc4 KMS driver owns the V3D (20c00000.v3d is bound to vc4_v3d): the firmware "
	                         "refuses QPU mailbox calls", 0), 0u) << r.reason;
	EXPECT_TRUE(contains(r.reason, "remove dtoverlay=vc4-kms-v3d")) << r.reason;
	EXPECT_TRUE(os.messages.empty()); // no mailbox call that could wedge the GPU
}

TEST(RuntimeProbe, KmsOverlayEnablesTheDevicetreeNode)
{
	FakeOs os;
	os.pi();
	os.dirs["/proc/device-tree/soc"] = {"gpio@7e200000", "v3d@7ec00000"};
	os.files["/proc/device-tree/soc/v3d@7ec00000/status"] = std::string("okay") + '\0';
	EXPECT_TRUE(contains(GpuDevice::probe(os).reason, "devicetree node v3d@7ec00000 is enabled"));
	os.files["/proc/device-tree/soc/v3d@7ec00000/status"] = std::string("disabled") + '\0';
	os.dmaHeap();
	EXPECT_TRUE(GpuDevice::probe(os).usable);
}

TEST(RuntimeProbe, MailboxDeviceMissingOrForbidden)
{
	FakeOs os;
	os.pi();
	os.devices.erase("/dev/vcio");
	EXPECT_EQ(GpuDevice::probe(os).reason,
	          "cannot enable the QPUs: /dev/vcio does not exist: not a Raspberry Pi kernel with the vcio "
	          "mailbox driver (CONFIG_BCM2835_VCIO)");
	os.open_errors["/dev/vcio"] = -EACCES;
	EXPECT_TRUE(contains(GpuDevice::probe(os).reason,
	                     "cannot enable the QPUs: permission denied opening /dev/vcio: run as root"));
}

TEST(RuntimeProbe, FirmwareRefusesToEnable)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	os.enable_status = 0x80000000;
	const auto r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_TRUE(contains(r.reason, "the firmware refused to enable the QPUs (status 0x80000000)")) << r.reason;
	// The request was the documented one.
	ASSERT_EQ(os.messages.size(), 2u);
	EXPECT_EQ(os.messages[1], (Words{28, 0, 0x00030012, 4, 0, 1, 0}));
}

TEST(RuntimeProbe, DmaHeapPathIsPreferred)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	os.devices.insert("/dev/mem");
	const auto r = GpuDevice::probe(os);
	ASSERT_TRUE(r.usable) << r.reason;
	EXPECT_EQ(r.memory, MemoryKind::DmaHeapVcsm);
	EXPECT_EQ(r.heap, "/dev/dma_heap/vidbuf_cached");
	EXPECT_EQ(r.v3d_hz, 300'000'000u);
	EXPECT_EQ(r.soc, "bcm2835");
	// firmware revision, enable, clock, disable again (the probe leaves the QPUs as found).
	ASSERT_EQ(os.messages.size(), 4u);
	EXPECT_EQ(os.messages[0], (Words{28, 0, 0x00000001, 4, 0, 0, 0}));
	EXPECT_EQ(os.messages[1], (Words{28, 0, 0x00030012, 4, 0, 1, 0}));
	EXPECT_EQ(os.messages[2], (Words{32, 0, 0x00030002, 8, 0, 5, 0, 0}));
	EXPECT_EQ(os.messages[3], (Words{28, 0, 0x00030012, 4, 0, 0, 0}));
	EXPECT_TRUE(os.open_fds.empty());
	EXPECT_EQ(r.summary(), "VideoCore IV QPUs usable\n  model: Raspberry Pi Zero W Rev 1.1 (bcm2835)\n"
	                       "  firmware revision: 0x5f5e1000\n  v3d clock: 300 MHz\n"
	                       "  memory: dma-heap + vcsm-cma (/dev/dma_heap/vidbuf_cached)");
}

TEST(RuntimeProbe, SecondHeapWhenTheFirstIsMissing)
{
	FakeOs os;
	os.pi();
	os.devices.insert("/dev/vcsm-cma");
	os.devices.insert("/dev/dma_heap/linux,cma");
	const auto r = GpuDevice::probe(os);
	ASSERT_TRUE(r.usable) << r.reason;
	EXPECT_EQ(r.heap, "/dev/dma_heap/linux,cma");
}

TEST(RuntimeProbe, FallsBackToMailboxMemoryThenGivesUp)
{
	FakeOs os;
	os.pi();
	os.devices.insert("/dev/dma_heap/vidbuf_cached"); // no /dev/vcsm-cma
	os.devices.insert("/dev/mem");
	auto r = GpuDevice::probe(os);
	ASSERT_TRUE(r.usable) << r.reason;
	EXPECT_EQ(r.memory, MemoryKind::MailboxDevMem);
	EXPECT_EQ(r.memory_note, "/dev/vcsm-cma does not exist, so dma-heap buffers cannot be given a bus address");
	// The trial allocation: 4096 bytes, 4096 aligned, flags 0xC on BCM2835, then released.
	EXPECT_EQ(os.messages[3], (Words{36, 0, 0x0003000c, 12, 0, 4096, 4096, 0xC, 0}));
	EXPECT_EQ(os.messages[4], (Words{28, 0, 0x0003000f, 4, 0, 7, 0}));

	os.open_errors["/dev/mem"] = -EACCES;
	r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_EQ(r.reason, "no GPU-visible memory: /dev/vcsm-cma does not exist, so dma-heap buffers cannot be "
	                    "given a bus address; legacy mailbox memory needs permission denied on /dev/mem (udev "
	                    "rule and group video, see vc4/BRINGUP.md) (root)");

	DeviceOptions no_legacy;
	no_legacy.allow_mailbox_memory = false;
	os.open_errors.clear();
	EXPECT_FALSE(GpuDevice::probe(os, no_legacy).usable);
}

TEST(RuntimeProbe, ImportFailureIsNamed)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	os.next_dma_addr = 0; // vcsm-cma gives no address
	const auto r = GpuDevice::probe(os);
	EXPECT_FALSE(r.usable);
	EXPECT_TRUE(contains(r.reason, "/dev/vcsm-cma import of a /dev/dma_heap/vidbuf_cached buffer failed: no bus address"))
		<< r.reason;
}

TEST(RuntimeDevice, UnusableDeviceThrowsTheReason)
{
	FakeOs os;
	try {
		GpuDevice d(os);
		FAIL();
	} catch (const RuntimeError &e) {
		EXPECT_STREQ(e.what(), "VideoCore IV QPUs not usable: not a Raspberry Pi: /proc/device-tree/model is missing");
	}
}

TEST(RuntimeDevice, DmaHeapBuffersAndALaunch)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	std::vector<uint32_t> control_bus;
	{
		GpuDevice d(os);
		const size_t before = os.messages.size();
		const auto code = d.upload(std::vector<uint64_t>{0x100009e7009e7000ull, 0x300009e7009e7000ull});
		// vcsm-cma's dma_addr 0x1F020000 seen through the uncached alias (the probe's trial
		// buffer had 0x1F000000, the launch control block 0x1F010000).
		EXPECT_EQ(code.bus, 0xDF020000u);
		EXPECT_EQ(code.cpu.size(), 16u);
		EXPECT_EQ(code.cpu[0], 0x00);
		EXPECT_EQ(code.cpu[15], 0x30);
		const auto unif = d.alloc(100);
		EXPECT_EQ(unif.bus, 0xDF030000u);
		EXPECT_EQ(unif.cpu.size(), 100u);
		EXPECT_EQ(unif.cpu[99], 0); // zeroed, not the mapping's garbage
		const auto big = d.alloc(5000, 16384);
		EXPECT_EQ(big.bus % 16384, 0u);

		os.log.clear();
		const Job jobs[] = {{unif.bus, code.bus}, {unif.bus + 4, code.bus}};
		const auto fence = d.launch(jobs, std::chrono::milliseconds(250));
		EXPECT_EQ(d.wait(fence).programs, 2u);
		EXPECT_THROW(d.wait(fence), std::invalid_argument);

		// Message: 2 programs, control block at the device's control buffer, flush, 250 ms.
		const Words &m = os.messages.at(before);
		ASSERT_EQ(m.size(), 10u);
		EXPECT_EQ((Words{m[0], m[1], m[2], m[3], m[4], m[5], m[7], m[8], m[9]}),
		          (Words{40, 0, 0x00030011, 16, 0, 2, 0, 250, 0}));
		EXPECT_EQ(m[6], 0xDF010000u); // the control block is the device's first buffer
		ASSERT_EQ(os.control_blocks.size(), 1u);
		EXPECT_EQ(os.control_blocks[0], (Words{unif.bus, code.bus, unif.bus + 4, code.bus}));

		// Every buffer's CPU caches written back (END) before, invalidated (START) after.
		const std::vector<std::string> expected = {
			"sync dmabuf2 0x00000007", "sync dmabuf3 0x00000007", "sync dmabuf4 0x00000007",
			"sync dmabuf5 0x00000007", "ioctl /dev/vcio " + test::hex32(uapi::kIoctlMboxProperty) + " tag=0x00030011",
			"sync dmabuf2 0x00000003", "sync dmabuf3 0x00000003", "sync dmabuf4 0x00000003",
			"sync dmabuf5 0x00000003"};
		EXPECT_EQ(os.log, expected);

		EXPECT_THROW(d.launch({}), std::invalid_argument);
		std::vector<Job> thirteen(13);
		EXPECT_THROW(d.launch(thirteen), std::invalid_argument);
		d.release(big);
		EXPECT_THROW(d.release(big), std::invalid_argument);
	}
	// Everything closed, QPUs disabled last.
	EXPECT_TRUE(os.open_fds.empty());
	EXPECT_EQ(os.messages.back(), (Words{28, 0, 0x00030012, 4, 0, 0, 0}));
	EXPECT_EQ(os.entries("munmap").size(), 4u);
}

TEST(RuntimeDevice, AllocationGoesThroughHeapMapAndImport)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	GpuDevice d(os);
	os.log.clear();
	d.alloc(6000);
	const std::vector<std::string> expected = {
		"ioctl /dev/dma_heap/vidbuf_cached " + test::hex32(uapi::kIoctlDmaHeapAlloc) + " len=8192 -> dmabuf3",
		"mmap dmabuf3 8192 @0x00000000",
		"ioctl /dev/vcsm-cma " + test::hex32(uapi::kIoctlVcsmImportDmabuf) + " dmabuf3 cached=0 name=vc4-qpu",
		"sync dmabuf3 0x00000003"};
	EXPECT_EQ(os.log, expected);
}

TEST(RuntimeDevice, TimeoutResetsTheQpus)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	GpuDevice d(os);
	const auto code = d.alloc(64);
	const Job job{code.bus, code.bus};
	os.execute_status = 0x1;
	const size_t before = os.messages.size();
	try {
		d.launch(std::span(&job, 1), std::chrono::milliseconds(5000));
		FAIL();
	} catch (const TimeoutError &e) {
		EXPECT_STREQ(e.what(), "QPU launch of 1 programs did not end within 900 ms (execute_qpu status "
		                       "0x00000001); the QPUs were reset");
	}
	ASSERT_EQ(os.messages.size(), before + 3);
	EXPECT_EQ(os.messages[before][8], 900u); // the timeout was clamped below the kernel's 1 s
	EXPECT_EQ(os.messages[before + 1], (Words{28, 0, 0x00030012, 4, 0, 0, 0}));
	EXPECT_EQ(os.messages[before + 2], (Words{28, 0, 0x00030012, 4, 0, 1, 0}));
	// The CPU's access window was reopened even though the launch failed.
	EXPECT_EQ(os.entries("sync").back(), "sync dmabuf3 0x00000003");

	// The kernel's own mailbox timeout is a timeout too.
	os.execute_status = 0;
	os.execute_errno = -ETIMEDOUT;
	EXPECT_THROW(d.launch(std::span(&job, 1)), TimeoutError);
	// Other ioctl failures are not.
	os.execute_errno = -EIO;
	try {
		d.launch(std::span(&job, 1));
		FAIL();
	} catch (const TimeoutError &) {
		FAIL();
	} catch (const RuntimeError &e) {
		EXPECT_TRUE(contains(e.what(), "QPU launch failed: mailbox tag 0x00030011: ioctl failed")) << e.what();
	}
	os.execute_errno = 0;
	EXPECT_NO_THROW(d.launch(std::span(&job, 1)));
}

TEST(RuntimeDevice, MailboxMemoryOnBcm2835AndBcm2837)
{
	for (const std::string soc : {"bcm2835", "bcm2837"}) {
		FakeOs os;
		os.pi(soc == "bcm2835" ? "Raspberry Pi Zero W Rev 1.1" : "Raspberry Pi Zero 2 W Rev 1.0", soc);
		os.devices.insert("/dev/mem");
		const uint32_t flags = soc == "bcm2835" ? 0xC : 0x4;
		{
			GpuDevice d(os);
			EXPECT_EQ(d.report().memory, MemoryKind::MailboxDevMem);
			os.log.clear();
			const size_t before = os.messages.size();
			const auto b = d.alloc(5000);
			EXPECT_EQ(os.messages[before], (Words{36, 0, 0x0003000c, 12, 0, 8192, 4096, flags, 0}));
			EXPECT_EQ(os.messages[before + 1], (Words{28, 0, 0x0003000d, 4, 0, 9, 0}));
			EXPECT_EQ(b.bus, 0xDE200000u);
			EXPECT_EQ(os.entries("mmap"), (std::vector<std::string>{"mmap /dev/mem 8192 @0x1e200000"}));
			EXPECT_EQ(b.cpu[4999], 0);
			const Job job{b.bus, b.bus};
			d.launch(std::span(&job, 1));
			EXPECT_TRUE(os.entries("sync").empty()); // uncached: nothing to sync
			d.release(b);
			EXPECT_EQ(os.messages[os.messages.size() - 2], (Words{28, 0, 0x0003000e, 4, 0, 9, 0}));
			EXPECT_EQ(os.messages.back(), (Words{28, 0, 0x0003000f, 4, 0, 9, 0}));
		}
		EXPECT_TRUE(os.open_fds.empty());
	}
}

// Camera frames (dma-bufs made elsewhere) imported in place: once per buffer, keyed by the
// file and not the fd number, bounded, synced around launches, released.
namespace {

// The message of the RuntimeError `f` throws; fails the test when it throws none.
template <class F>
std::string errorOf(F &&f)
{
	try {
		f();
	} catch (const RuntimeError &e) {
		return e.what();
	}
	ADD_FAILURE() << "no RuntimeError";
	return {};
}

size_t countOf(const std::vector<std::string> &log, const std::string &part)
{
	return static_cast<size_t>(std::count_if(log.begin(), log.end(), [&](const std::string &l) { return contains(l, part); }));
}

} // namespace

TEST(RuntimeImport, OncePerBufferOverManyFramesAndSyncedAroundLaunches)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	const int cam[3] = {os.cameraBuffer("cam0", 320 * 240, 100), os.cameraBuffer("cam1", 320 * 240, 101),
	                    os.cameraBuffer("cam2", 320 * 240, 102)};
	{
		GpuDevice d(os);
		const auto code = d.upload(std::vector<uint64_t>{0x100009e7009e7000ull});
		os.log.clear();
		uint32_t bus[3] = {};
		for (int frame = 0; frame < 12; ++frame) {
			const auto im = d.importDmabuf(cam[frame % 3]);
			EXPECT_EQ(im.bytes, 320u * 240u);
			if (frame < 3)
				bus[frame] = im.bus;
			EXPECT_EQ(im.bus, bus[frame % 3]) << "frame " << frame;
			EXPECT_EQ(im.bus & 0xC0000000u, 0xC0000000u); // the uncached alias
		}
		EXPECT_NE(bus[0], bus[1]);
		EXPECT_EQ(d.imports(), 3u);
		EXPECT_EQ(countOf(os.log, "name=vc4-frame"), 3u); // one vcsm-cma import a buffer
		EXPECT_EQ(countOf(os.log, "dup cam"), 3u);
		os.log.clear();
		const Job job{code.bus, code.bus};
		d.wait(d.launch(std::span<const Job>(&job, 1)));
		// Each imported frame written back before the launch and invalidated after, as the
		// device's own buffers.
		for (const char *c : {"cam0", "cam1", "cam2"}) {
			EXPECT_EQ(countOf(os.log, std::string("sync ") + c + " 0x00000007"), 1u) << c;
			EXPECT_EQ(countOf(os.log, std::string("sync ") + c + " 0x00000003"), 1u) << c;
		}
		const auto launch = std::find_if(os.log.begin(), os.log.end(), [](const std::string &l) { return contains(l, "tag=0x00030011"); });
		ASSERT_NE(launch, os.log.end());
		EXPECT_EQ(std::count_if(os.log.begin(), launch, [](const std::string &l) { return contains(l, "sync cam"); }), 3);
		EXPECT_EQ(std::count_if(launch, os.log.end(), [](const std::string &l) { return contains(l, "sync cam"); }), 3);
	}
	// Destruction released the imports and our dups; the caller's fds stay open.
	EXPECT_EQ(os.open_fds.size(), 3u);
	for (int fd : cam)
		EXPECT_EQ(os.close(fd), 0);
	EXPECT_TRUE(os.open_fds.empty());
}

TEST(RuntimeImport, RecycledFdNumberOfAnotherBufferIsImportedAfresh)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	GpuDevice d(os);
	const int fd = os.cameraBuffer("camA", 4096, 200);
	const auto a = d.importDmabuf(fd);
	os.close(fd);
	// The same number now names another buffer: a new import, not the old bus address.
	ASSERT_EQ(os.cameraBuffer("camB", 8192, 201, fd), fd);
	const auto b = d.importDmabuf(fd);
	EXPECT_NE(a.bus, b.bus);
	EXPECT_EQ(b.bytes, 8192u);
	EXPECT_EQ(d.imports(), 2u);
	// Another number for the same buffer (as a pool's dup would be) hits the cache.
	const int again = os.dup(fd);
	os.log.clear();
	EXPECT_EQ(d.importDmabuf(again).bus, b.bus);
	EXPECT_EQ(countOf(os.log, "vcsm-cma"), 0u);
	os.close(again);
	os.close(fd);
}

TEST(RuntimeImport, BoundedLeastRecentlyUsedFirstAndReleased)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	GpuDevice d(os);
	constexpr size_t kCap = ImportCache<int>::kCapacity;
	std::vector<int> fds;
	for (size_t i = 0; i <= kCap; ++i)
		fds.push_back(os.cameraBuffer("cam" + std::to_string(i), 4096, 300 + i));
	for (size_t i = 0; i < kCap; ++i)
		d.importDmabuf(fds[i]);
	d.importDmabuf(fds[0]); // cam0 used again: cam1 is now the oldest
	os.log.clear();
	d.importDmabuf(fds[kCap]);
	EXPECT_EQ(d.imports(), kCap);
	// cam1's import and our dup of it closed; cam0 still cached.
	EXPECT_EQ(countOf(os.log, "close import-of-cam1"), 1u);
	EXPECT_EQ(countOf(os.log, "close cam1"), 1u);
	os.log.clear();
	d.importDmabuf(fds[0]);
	EXPECT_EQ(countOf(os.log, "vcsm-cma"), 0u);
	for (int fd : fds)
		os.close(fd);
}

TEST(RuntimeImport, RefusedImportSaysWhyAndLeaksNothing)
{
	FakeOs os;
	os.pi();
	os.dmaHeap();
	GpuDevice d(os);
	const int fd = os.cameraBuffer("scattered", 4096, 400);
	os.refuse_import.insert("scattered");
	const size_t open_before = os.open_fds.size();
	const std::string refused = errorOf([&] { d.importDmabuf(fd); });
	EXPECT_TRUE(contains(refused, "/dev/vcsm-cma refused to import dma-buf fd " + std::to_string(fd))) << refused;
	EXPECT_EQ(os.open_fds.size(), open_before);
	EXPECT_EQ(d.imports(), 0u);
	// The refusal is remembered for the buffer: later frames cost an fstat, not an import.
	os.log.clear();
	std::string_view why;
	EXPECT_EQ(d.tryImportDmabuf(fd, why), nullptr);
	EXPECT_EQ(why, refused);
	EXPECT_TRUE(os.log.empty());
	const std::string closed = errorOf([&] { d.importDmabuf(999); });
	EXPECT_TRUE(contains(closed, "fstat of dma-buf fd 999 failed")) << closed;
	os.close(fd);
}

TEST(RuntimeImport, MailboxMemoryCannotImport)
{
	FakeOs os;
	os.pi();
	os.devices.insert("/dev/mem");
	GpuDevice d(os);
	ASSERT_EQ(d.report().memory, MemoryKind::MailboxDevMem);
	const int fd = os.cameraBuffer("cam", 4096, 500);
	const std::string why = errorOf([&] { d.importDmabuf(fd); });
	EXPECT_TRUE(contains(why, "dma-buf import needs vcsm-cma, and this device uses mailbox + /dev/mem memory")) << why;
	os.close(fd);
}

TEST(RuntimeImport, FrameMemoryFromTheRuntimesHeap)
{
	FakeOs os;
	os.dmaHeap();
	std::string why;
	const int fd = allocateDmaHeapBuffer(os, DeviceOptions{}, 640 * 480, why);
	ASSERT_GE(fd, 0) << why;
	EXPECT_EQ(os.open_fds.at(fd), "dmabuf1");
	EXPECT_EQ(countOf(os.log, "len=307200 -> dmabuf1"), 1u); // 75 pages exactly
	os.close(fd);
	EXPECT_TRUE(os.open_fds.empty()); // the heap's fd is not kept

	FakeOs none;
	EXPECT_EQ(allocateDmaHeapBuffer(none, DeviceOptions{}, 4096, why), -1);
	EXPECT_EQ(why, "no dma-heap frame memory: /dev/dma_heap/vidbuf_cached does not exist; "
	               "/dev/dma_heap/linux,cma does not exist");
}

// Issue 34: the probe read /proc/device-tree/model with no limit: a FIFO there hung
// --backend vc4, /dev/zero grew memory without end. What is opened is checked first.
TEST(RuntimeOs, ReadFileRefusesFifosDevicesAndLargeFiles)
{
	char dir[] = "/tmp/frappe-vc4-os-XXXXXX";
	ASSERT_NE(::mkdtemp(dir), nullptr);
	const std::string fifo = std::string(dir) + "/model", small = std::string(dir) + "/small",
	                  large = std::string(dir) + "/large";
	ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
	// A thread polled, not std::future: libstdc++ has no timed futex wait on ARMv6.
	std::atomic<bool> done{ false };
	std::optional<std::string> got = std::string("not read");
	std::thread reader([&] {
		got = systemOs().readFile(fifo);
		done = true;
	});
	const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(3);
	while (!done && std::chrono::steady_clock::now() < end)
		std::this_thread::sleep_for(std::chrono::milliseconds(5));
	if (!done) {
		ADD_FAILURE() << "readFile blocked on a FIFO";
		const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK); // set it free
		if (fd >= 0)
			::close(fd);
	}
	reader.join();
	EXPECT_EQ(got, std::nullopt);
	EXPECT_EQ(systemOs().readFile("/dev/zero"), std::nullopt);
	std::ofstream(small) << "Raspberry Pi Zero W Rev 1.1";
	EXPECT_EQ(systemOs().readFile(small), "Raspberry Pi Zero W Rev 1.1");
	std::ofstream(large) << std::string(Os::kMaxReadFileBytes + 1, 'x');
	EXPECT_EQ(systemOs().readFile(large), std::nullopt);
	for (const std::string &f : { fifo, small, large })
		::unlink(f.c_str());
	::rmdir(dir);
}
