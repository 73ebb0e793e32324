// SPDX-License-Identifier: MIT
// Built against an installed frappe (tests/install): runs a detector on a
// blank frame and prints the library's version.
#include <cstdint>
#include <cstdio>
#include <vector>

#include <frappe/frappe.h>

int main()
{
	frappe::Config config;
	config.dictionary = "apriltag_36h11";
	frappe::Detector detector(config);

	constexpr int width = 320, height = 240;
	std::vector<std::uint8_t> frame(width * height, 128);
	const frappe::Result &result = detector.detect({ frame.data(), width, height });

	std::printf("frappe %s markers %zu\n", frappe::version(), result.markers.size());
	return 0;
}
