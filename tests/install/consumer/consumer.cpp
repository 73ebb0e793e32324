// SPDX-License-Identifier: MIT
// Built against an installed frappe (tests/install): runs a detector on a
// blank frame and prints the library's version, which must be the headers'.
#include <cstdint>
#include <cstdio>
#include <string_view>
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
	static_assert(FRAPPE_VERSION_MAJOR >= 0 && FRAPPE_VERSION_MINOR >= 0 && FRAPPE_VERSION_PATCH >= 0);
	return std::string_view(frappe::version()) == FRAPPE_VERSION_STRING ? 0 : 1;
}
