// SPDX-License-Identifier: MIT
// Configure-time probe: can the cross compiler build a static ARMv6 C++ program?
#include <arm_acle.h>
#include <thread>
int main()
{
	std::thread t([] {});
	t.join();
	return static_cast<int>(__uxtb16(0u));
}
