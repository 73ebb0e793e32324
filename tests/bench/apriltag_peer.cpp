// SPDX-License-Identifier: MIT
// apriltag-peer: AprilTag 3.3 (Debian's libapriltag) on a list of images,
// writing the detector contract's JSON lines
// (../shared/design/DETECTOR-CONTRACT.md), for the AprilTag families frappe-bench does not
// run: the layout families of issue 32 (tagStandard41h12 and its kin), and
// the classic ones.
//
//   apriltag-peer --dictionary apriltag_standard41h12 --list LIST.txt --out D.jsonl [--decimate 1] [--hamming 2]
//
// Corners as the contract has them: AprilTag's run the other way round,
// one corner later (three for the layout families), with pixel centres at
// +0.5.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>

namespace {

struct Family {
	const char *name;
	apriltag_family_t *(*create)();
	void (*destroy)(apriltag_family_t *);
};

const Family kFamilies[] = {
	{ "apriltag_16h5", tag16h5_create, tag16h5_destroy },
	{ "apriltag_25h9", tag25h9_create, tag25h9_destroy },
	{ "apriltag_36h11", tag36h11_create, tag36h11_destroy },
	{ "apriltag_circle21h7", tagCircle21h7_create, tagCircle21h7_destroy },
	{ "apriltag_circle49h12", tagCircle49h12_create, tagCircle49h12_destroy },
	{ "apriltag_custom48h12", tagCustom48h12_create, tagCustom48h12_destroy },
	{ "apriltag_standard41h12", tagStandard41h12_create, tagStandard41h12_destroy },
	{ "apriltag_standard52h13", tagStandard52h13_create, tagStandard52h13_destroy },
};

} // namespace

int main(int argc, char **argv)
{
	std::string dictionary, list, out;
	float decimate = 1.0f;
	int hamming = 2;
	for (int i = 1; i + 1 < argc; i += 2) {
		const std::string a = argv[i];
		if (a == "--dictionary")
			dictionary = argv[i + 1];
		else if (a == "--list")
			list = argv[i + 1];
		else if (a == "--out")
			out = argv[i + 1];
		else if (a == "--decimate")
			decimate = std::stof(argv[i + 1]);
		else if (a == "--hamming")
			hamming = std::stoi(argv[i + 1]);
	}
	const Family *family = nullptr;
	for (const Family &f : kFamilies)
		if (dictionary == f.name)
			family = &f;
	if (!family || list.empty() || out.empty()) {
		std::cerr << "usage: apriltag-peer --dictionary apriltag_standard41h12|... --list L --out D.jsonl "
			     "[--decimate 1] [--hamming 2]\n";
		return 2;
	}
	apriltag_family_t *tf = family->create();
	apriltag_detector_t *det = apriltag_detector_create();
	/* libapriltag's quick-decode table for the 48714- and 65535-code
	 * families at 2 bits takes gigabytes: 1 bit there. */
	apriltag_detector_add_family_bits(det, tf, hamming);
	det->nthreads = 1;
	det->quad_decimate = decimate;
	/* Measured on renders with known corners: the layout families' corners
	 * start two corners later than the classic ones' (tag36h11's, as
	 * frappe-bench converts them). */
	const bool layoutFamily = dictionary.find("standard") != std::string::npos ||
				  dictionary.find("circle") != std::string::npos ||
				  dictionary.find("custom") != std::string::npos;
	const int turn = layoutFamily ? 3 : 1;
	std::ifstream in(list);
	std::ofstream o(out);
	std::string path;
	while (std::getline(in, path)) {
		if (path.empty() || path[0] == '#')
			continue;
		cv::Mat g = cv::imread(path, cv::IMREAD_GRAYSCALE);
		if (g.empty()) {
			o << "{\"image\": \"" << path << "\", \"markers\": [], \"error\": \"unreadable\"}\n";
			continue;
		}
		image_u8_t im{ g.cols, g.rows, static_cast<int32_t>(g.step[0]), g.data };
		const auto t0 = std::chrono::steady_clock::now();
		zarray_t *found = apriltag_detector_detect(det, &im);
		const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
		o << "{\"image\": \"" << path << "\", \"markers\": [";
		for (int i = 0; i < zarray_size(found); ++i) {
			apriltag_detection_t *d;
			zarray_get(found, i, &d);
			char buf[256];
			std::snprintf(buf, sizeof(buf), "%s{\"id\": %d, \"corners\": [", i ? ", " : "", d->id);
			o << buf;
			for (int k = 0; k < 4; ++k) {
				const int from = (turn - k) & 3;
				std::snprintf(buf, sizeof(buf), "%s[%.3f, %.3f]", k ? ", " : "", d->p[from][0] - 0.5,
					      d->p[from][1] - 0.5);
				o << buf;
			}
			o << "]}";
		}
		char t[64];
		std::snprintf(t, sizeof(t), "], \"time_ms\": %.3f}\n", ms);
		o << t;
		apriltag_detections_destroy(found);
	}
	apriltag_detector_destroy(det);
	family->destroy(tf);
	return 0;
}
