// SPDX-License-Identifier: MIT
// Drawing detections over an image, for people to look at.
#pragma once

#include <span>

#include <opencv2/core.hpp>

#include "frappe/marker.h"

namespace frappe::cli {

/// A colour copy of `gray` with each marker's outline, its first corner
/// (the marker's top-left) and its id drawn on.
cv::Mat annotate(const cv::Mat &gray, std::span<const Marker> markers);

} // namespace frappe::cli
