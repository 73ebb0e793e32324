// SPDX-License-Identifier: MIT
// Our own declarations of the kernel interfaces the real-GPU runtime uses, so that the
// runtime builds (and its encodings are tested) on any Linux machine. Every number below
// is derived from the public uapi definitions named beside it; the tests compare them
// with the system headers where those exist (dma-buf, dma-heap) and pin the rest.
#pragma once

#include <cstddef>
#include <cstdint>

namespace frappe::vc4::runtime::uapi {

// Linux asm-generic ioctl number layout (include/uapi/asm-generic/ioctl.h): bits 31:30
// direction (1 write, 2 read, 3 both, seen from user space), 29:16 argument size,
// 15:8 type ("magic"), 7:0 command number. ARM and x86 use this generic layout.
inline constexpr uint32_t kIocWrite = 1;
inline constexpr uint32_t kIocRead = 2;
constexpr uint32_t ioc(uint32_t dir, uint32_t type, uint32_t nr, uint32_t size)
{
	return dir << 30 | size << 16 | type << 8 | nr;
}

// ---- /dev/vcio: the firmware mailbox property interface -------------------------------
// raspberrypi/linux drivers/char/broadcom/vcio.c: IOCTL_MBOX_PROPERTY is
// _IOWR(100, 0, char *): the size field is the size of a user pointer, so it differs
// between 32-bit (0xC0046400) and 64-bit (0xC0086400) processes; the driver accepts the
// 32-bit number from compat tasks.
inline constexpr uint32_t kVcioMagic = 100;
constexpr uint32_t mboxPropertyIoctl(uint32_t pointer_bytes)
{
	return ioc(kIocRead | kIocWrite, kVcioMagic, 0, pointer_bytes);
}
inline constexpr unsigned long kIoctlMboxProperty = mboxPropertyIoctl(sizeof(void *));

// Property message codes (Raspberry Pi firmware wiki "Mailbox property interface";
// include/soc/bcm2835/raspberrypi-firmware.h).
inline constexpr uint32_t kProcessRequest = 0x00000000;
inline constexpr uint32_t kResponseSuccess = 0x80000000;
inline constexpr uint32_t kResponseError = 0x80000001;
inline constexpr uint32_t kTagResponse = 0x80000000; // bit 31 of a tag's req/resp word
inline constexpr uint32_t kEndTag = 0;

namespace tag {
inline constexpr uint32_t firmware_revision = 0x00000001;
inline constexpr uint32_t board_model = 0x00010001;
inline constexpr uint32_t board_revision = 0x00010002;
inline constexpr uint32_t clock_rate = 0x00030002;
inline constexpr uint32_t allocate_memory = 0x0003000c;
inline constexpr uint32_t lock_memory = 0x0003000d;
inline constexpr uint32_t unlock_memory = 0x0003000e;
inline constexpr uint32_t release_memory = 0x0003000f;
inline constexpr uint32_t execute_qpu = 0x00030011;
inline constexpr uint32_t set_enable_qpu = 0x00030012;
} // namespace tag

// Clock ids of the get-clock-rate tag; the V3D (QPU) clock is 5.
inline constexpr uint32_t kClockV3d = 5;

// allocate_memory flags (hello_fft and the firmware wiki): DIRECT = 0xC alias (uncached),
// COHERENT = 0x8 alias (L2 only); hello_fft uses DIRECT|COHERENT (0xC, "L1 non-allocating")
// on BCM2835 and DIRECT (0x4) on BCM2836/7.
inline constexpr uint32_t kMemFlagDirect = 1u << 2;
inline constexpr uint32_t kMemFlagCoherent = 2u << 2;
inline constexpr uint32_t kMemFlagL1NonAllocating = kMemFlagDirect | kMemFlagCoherent;

// VC bus aliases: bits 31:30 of a bus address choose the cache behaviour; 0xC0000000 is
// the uncached (L2-bypassing) alias used for memory the ARM also touches.
inline constexpr uint32_t kBusAliasMask = 0xC0000000u;
inline constexpr uint32_t kBusAliasUncached = 0xC0000000u;

// ---- dma-heap (include/uapi/linux/dma-heap.h) ----------------------------------------
struct DmaHeapAllocationData {
	uint64_t len = 0;        // in: bytes
	uint32_t fd = 0;         // out: the new dma-buf
	uint32_t fd_flags = 0;   // in: O_RDWR | O_CLOEXEC
	uint64_t heap_flags = 0; // in: must be 0
};
static_assert(sizeof(DmaHeapAllocationData) == 24);
static_assert(offsetof(DmaHeapAllocationData, fd) == 8);
static_assert(offsetof(DmaHeapAllocationData, fd_flags) == 12);
static_assert(offsetof(DmaHeapAllocationData, heap_flags) == 16);
inline constexpr uint32_t kDmaHeapMagic = 'H';
inline constexpr unsigned long kIoctlDmaHeapAlloc =
	ioc(kIocRead | kIocWrite, kDmaHeapMagic, 0, sizeof(DmaHeapAllocationData));

// ---- dma-buf CPU access bracketing (include/uapi/linux/dma-buf.h) ---------------------
struct DmaBufSync {
	uint64_t flags = 0;
};
static_assert(sizeof(DmaBufSync) == 8);
inline constexpr uint64_t kDmaBufSyncRead = 1;
inline constexpr uint64_t kDmaBufSyncWrite = 2;
inline constexpr uint64_t kDmaBufSyncRw = 3;
inline constexpr uint64_t kDmaBufSyncStart = 0;
inline constexpr uint64_t kDmaBufSyncEnd = 4;
inline constexpr uint32_t kDmaBufMagic = 'b';
inline constexpr unsigned long kIoctlDmaBufSync = ioc(kIocWrite, kDmaBufMagic, 0, sizeof(DmaBufSync));

// ---- /dev/vcsm-cma (raspberrypi/linux include/uapi/linux/vc_sm_cma_ioctl.h) ------------
// Commands start at 0x5A (ALLOC); IMPORT_DMABUF is the next one. The import gives the
// VideoCore bus address of an imported dma-buf and a new dma-buf fd that keeps the
// VideoCore mapping alive.
inline constexpr uint32_t kVcsmMagic = 'J';
inline constexpr uint32_t kVcsmCmdAlloc = 0x5A;
inline constexpr uint32_t kVcsmCmdImportDmabuf = 0x5B;
inline constexpr uint32_t kVcsmCacheNone = 0;
struct VcsmImportDmabuf {
	int32_t dmabuf_fd = -1;   // in
	uint32_t cached = 0;      // in: enum vc_sm_cma_cache_e
	uint8_t name[32] = {};    // in
	int32_t handle = -1;      // out: dma-buf fd of the import
	uint32_t vc_handle = 0;   // out
	uint32_t size = 0;        // out
	uint32_t pad = 0;
	uint64_t dma_addr = 0;    // out: bus address
};
static_assert(sizeof(VcsmImportDmabuf) == 64);
static_assert(offsetof(VcsmImportDmabuf, name) == 8);
static_assert(offsetof(VcsmImportDmabuf, handle) == 40);
static_assert(offsetof(VcsmImportDmabuf, vc_handle) == 44);
static_assert(offsetof(VcsmImportDmabuf, size) == 48);
static_assert(offsetof(VcsmImportDmabuf, dma_addr) == 56);
inline constexpr unsigned long kIoctlVcsmImportDmabuf =
	ioc(kIocRead, kVcsmMagic, kVcsmCmdImportDmabuf, sizeof(VcsmImportDmabuf));

// The numbers the tests pin (independent of the helper above).
static_assert(mboxPropertyIoctl(4) == 0xC0046400u);
static_assert(mboxPropertyIoctl(8) == 0xC0086400u);
static_assert(kIoctlDmaHeapAlloc == 0xC0184800u);
static_assert(kIoctlDmaBufSync == 0x40086200u);
static_assert(kIoctlVcsmImportDmabuf == 0x80404A5Bu);

} // namespace frappe::vc4::runtime::uapi
