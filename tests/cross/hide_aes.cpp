// SPDX-License-Identifier: MIT
// LD_PRELOAD shim for the aarch64 tests: getauxval(AT_HWCAP) without the AES
// and PMULL bits, as on the Cortex-A53 of a Raspberry Pi Zero 2 W (qemu's
// cortex-a53 model has them, and its CPU features cannot be switched off).
// Highway reads the CPU's features through getauxval.
#include <dlfcn.h>
#include <sys/auxv.h>

extern "C" __attribute__((visibility("default"))) unsigned long getauxval(unsigned long type)
{
	using Fn = unsigned long (*)(unsigned long);
	static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "getauxval"));
	const unsigned long value = real ? real(type) : 0;
	return type == AT_HWCAP ? value & ~(HWCAP_AES | HWCAP_PMULL) : value;
}
