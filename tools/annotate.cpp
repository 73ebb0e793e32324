// SPDX-License-Identifier: MIT
#include "annotate.h"

#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace frappe::cli {

cv::Mat annotate(const cv::Mat &gray, std::span<const Marker> markers)
{
	cv::Mat out;
	cv::cvtColor(gray, out, cv::COLOR_GRAY2BGR);
	constexpr int shift = 4; /* sub-pixel drawing, 1/16 px */
	auto fix = [](Point2f p) {
		/* Both OpenCV and Frappe put pixel centres at integers. */
		return cv::Point(static_cast<int>(std::lround(p.x * 16.0f)), static_cast<int>(std::lround(p.y * 16.0f)));
	};
	for (const Marker &m : markers) {
		std::vector<cv::Point> poly;
		for (const Point2f &p : m.corners)
			poly.push_back(fix(p));
		cv::polylines(out, poly, true, cv::Scalar(0, 255, 0), 2, cv::LINE_AA, shift);
		cv::circle(out, poly[0], 4 << shift, cv::Scalar(0, 0, 255), 2, cv::LINE_AA, shift);
		float cx = 0, cy = 0;
		for (const Point2f &p : m.corners) {
			cx += p.x / 4;
			cy += p.y / 4;
		}
		const std::string label = std::to_string(m.id);
		int base = 0;
		const cv::Size sz = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.6, 2, &base);
		const cv::Point org(static_cast<int>(cx) - sz.width / 2, static_cast<int>(cy) + sz.height / 2);
		cv::putText(out, label, org, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
		cv::putText(out, label, org, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 0), 2, cv::LINE_AA);
	}
	return out;
}

} // namespace frappe::cli
