// SPDX-License-Identifier: MIT
// A frappe dictionary as OpenCV aruco's custom Dictionary, so that the peer
// decodes exactly the same codewords (frappe-bench and frappe-count).
#pragma once

#include <cstdint>

#include <opencv2/aruco.hpp>

#include "frappe/dictionary.h"

inline cv::Ptr<cv::aruco::Dictionary> opencvDictionary(const frappe::Dictionary &d, int maxCorrection)
{
	auto dict = cv::makePtr<cv::aruco::Dictionary>();
	dict->markerSize = d.bits;
	dict->maxCorrectionBits = maxCorrection;
	const int n = d.bits;
	for (int id = 0; id < d.size(); ++id) {
		cv::Mat bits(n, n, CV_8UC1);
		for (int r = 0; r < n; ++r)
			for (int c = 0; c < n; ++c)
				bits.at<std::uint8_t>(r, c) =
					static_cast<std::uint8_t>((d.codes[id] >> (n * n - 1 - (r * n + c))) & 1u);
		dict->bytesList.push_back(cv::aruco::Dictionary::getByteListFromBits(bits));
	}
	return dict;
}
