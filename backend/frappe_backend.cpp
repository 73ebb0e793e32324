/* SPDX-License-Identifier: MIT
 *
 * frappe_backend.cpp: the front end a user names put into a detector, and
 * the frame memory its QPUs read in place.
 */
#include "frappe_backend.h"

#include <algorithm>
#include <iterator>
#include <utility>
#include <vector>

#ifdef FRAPPE_HAVE_VC4
#include "frontend/backend.hpp"
#endif

namespace frappe {

namespace {

constexpr BackendName kBackends[] = {
	{ "auto", "The Raspberry Pi's QPUs when they can be used, else the CPU (with one warning on a Pi)" },
	{ "cpu", "The reference CPU front end" },
	{ "vc4", "The QPU kernels on the VideoCore IV GPU (Pi Zero, 1, 2, 3)" },
	{ "vc4-emu", "The QPU kernels on an emulator: bit-exact with vc4, slow; for testing" },
};

} // namespace

std::span<const BackendName> backendNames()
{
	return kBackends;
}

std::string backendNameList(std::string_view separator)
{
	std::string out;
	for (const BackendName &b : kBackends)
		out += (out.empty() ? "" : std::string(separator)) + std::string(b.name);
	return out;
}

std::string selectBackend(Pipeline &pipeline, std::string_view name)
{
	if (std::none_of(std::begin(kBackends), std::end(kBackends),
			 [&](const BackendName &b) { return b.name == name; }))
		throw std::invalid_argument("unknown backend '" + std::string(name) + "' (" + backendNameList() + ")");
	/* The detectors' own front end already is the CPU one. */
	if (name == "cpu")
		return {};
#ifdef FRAPPE_HAVE_VC4
	std::string fallback;
	for (int i = 0; i < pipeline.detectorCount(); ++i) {
		vc4::BackendChoice choice = vc4::selectFrontEnd(name, 1);
		Detector &detector = pipeline.detector(i);
		detector.setFrontEnd(std::move(choice.frontEnd));
		detector.setWarper(std::move(choice.warper));
		if (fallback.empty())
			fallback = std::move(choice.fallback);
	}
	return fallback;
#else
	(void)pipeline;
	if (name == "auto")
		return {};
	throw BackendNotBuilt("backend " + std::string(name) + " needs vc4/, which this build lacks");
#endif
}

int qpuContexts(Pipeline &pipeline)
{
#ifdef FRAPPE_HAVE_VC4
	std::vector<const void *> seen;
	for (int i = 0; i < pipeline.detectorCount(); ++i) {
		const void *context = vc4::contextOf(pipeline.detector(i).frontEnd());
		if (context && std::find(seen.begin(), seen.end(), context) == seen.end())
			seen.push_back(context);
	}
	return static_cast<int>(seen.size());
#else
	(void)pipeline;
	return 0;
#endif
}

int allocateFrameMemory(std::string_view backend, std::size_t bytes, std::string &why)
{
#ifdef FRAPPE_HAVE_VC4
	return vc4::allocateFrameMemory(backend, bytes, why);
#else
	(void)bytes;
	why = "no frame memory for backend '" + std::string(backend) + "': this build has no vc4/";
	return -1;
#endif
}

} /* namespace frappe */
