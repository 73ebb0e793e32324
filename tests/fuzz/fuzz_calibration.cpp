// SPDX-License-Identifier: MIT
// libFuzzer target: a calibration file (parseCalibration, what
// readCalibration reads) and the YAML and XML subsets beneath it, any
// bytes. The promise: a file that is not a calibration is a
// std::invalid_argument whose message names the file and is UTF-8; one
// that is gives a camera that validates; the markup readers stay within
// their bounds of nesting and nodes (issue 34: the 15 minutes of an
// attacker's fuzzer found nothing; this keeps it so in CI).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "frappe/camera.h"
#include "markup.h"
#include "utf8.h"

namespace {

using frappe::detail::MarkupNode;

/* Aborts unless `e` names `origin` and, when it is what the user sees
 * (parseCalibration's, not the markup readers' beneath it), is UTF-8. */
void checkMessage(const std::invalid_argument &e, std::string_view origin, bool shown)
{
	const std::string_view what = e.what();
	if (what.substr(0, origin.size()) != origin ||
	    (shown && frappe::detail::invalidUtf8At(what) != std::string_view::npos))
		std::abort();
}

/* Nodes in the tree, aborting past the readers' bounds. */
int nodes(const MarkupNode &n, int depth)
{
	if (depth > frappe::detail::kMarkupMaxDepth + 1)
		std::abort();
	if (n.kind == MarkupNode::Kind::Map && n.keys.size() != n.items.size())
		std::abort();
	int count = 1;
	for (const MarkupNode &item : n.items)
		count += nodes(item, depth + 1);
	return count;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
	const std::string_view text(reinterpret_cast<const char *>(data), size);
	try {
		const frappe::Camera c = frappe::parseCalibration(text, "fuzz.yaml");
		if (!c.valid() || c.width < 0 || c.height < 0 || (c.width == 0) != (c.height == 0))
			std::abort();
		/* Scaling gives a camera or says why. */
		try {
			if (!c.scaledTo(1920, 1080).valid())
				std::abort();
		} catch (const std::invalid_argument &) {
		}
	} catch (const std::invalid_argument &e) {
		checkMessage(e, "fuzz.yaml", true);
	}
	try {
		if (nodes(frappe::detail::parseYamlSubset(text, "fuzz.yaml"), 0) > frappe::detail::kMarkupMaxNodes + 1)
			std::abort();
	} catch (const std::invalid_argument &e) {
		checkMessage(e, "fuzz.yaml", false);
	}
	try {
		std::string root;
		if (nodes(frappe::detail::parseXmlSubset(text, "fuzz.xml", root), 0) > frappe::detail::kMarkupMaxNodes + 1)
			std::abort();
	} catch (const std::invalid_argument &e) {
		checkMessage(e, "fuzz.xml", false);
	}
	return 0;
}
