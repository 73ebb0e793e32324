// SPDX-License-Identifier: MIT
// A detector's stages one at a time, for Pipeline's staged mode and the
// instruction counter: the front end, the contour trace and the rest (refine,
// warp, decode) of a frame, each frame in a slot of its own so that stages
// of different frames can run on different threads at once.
#pragma once

#include "frappe/detector.h"

namespace frappe::detail {

class DetectorStages
{
public:
	/// Frames in flight at once.
	static constexpr int kSlots = 3;

	/// Fills the slot's edge map. The image must stay valid until the
	/// slot's finish() returns. In AScale mode the scale of a frame comes
	/// from the last frame finished before its front end started. Throws
	/// std::invalid_argument for a bad image or slot.
	static void frontEnd(Detector &detector, const ImageView &image, int slot);
	/// Traces the slot's edge map into candidates.
	static void trace(Detector &detector, int slot);
	/// Refines, warps and decodes the slot's candidates.
	static const Result &finish(Detector &detector, const ImageView &image, int slot);

	static const Result &backEnd(Detector &detector, const ImageView &image, int slot)
	{
		trace(detector, slot);
		return finish(detector, image, slot);
	}
};

} // namespace frappe::detail
