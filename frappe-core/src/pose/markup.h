// SPDX-License-Identifier: MIT
// The small subsets of YAML and XML that calibration files are written in
// (ROS camera_info, OpenCV FileStorage), read into one tree. Hand-written
// and bounded: input size, nesting depth and node count are limited, and
// every error is a std::invalid_argument naming the origin and the line.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace frappe::detail {

struct MarkupNode {
	enum class Kind { Scalar, Map, Seq };
	Kind kind = Kind::Scalar;
	std::string text; ///< a scalar's text (XML: the element's text)
	std::string tag;  ///< "opencv-matrix" from !!opencv-matrix or type_id="opencv-matrix"
	int line = 0;
	std::vector<std::string> keys; ///< a map's keys, in order
	std::vector<MarkupNode> items; ///< a map's values or a sequence's items

	/// The value of `key` in a map, or nullptr.
	const MarkupNode *find(std::string_view key) const;
};

/// The most bytes parsed; calibration files are a few hundred.
constexpr std::size_t kMarkupMaxBytes = 1 << 20;
/// The deepest nesting accepted (calibration files use 2).
constexpr int kMarkupMaxDepth = 32;
/// The most nodes in one document.
constexpr int kMarkupMaxNodes = 65536;

/// Block mappings and sequences, flow [..] and {..} (also over several
/// lines), plain and quoted scalars, tags, comments, a %YAML directive and
/// ---. Not anchors, aliases or block scalars (| >): they are refused.
MarkupNode parseYamlSubset(std::string_view text, std::string_view origin);

/// Elements, attributes (type_id becomes the tag), text, comments, the
/// <?xml?> declaration and the five predefined entities and character
/// references. An element with children is a map of them, or a sequence
/// when they are all <_> (OpenCV's items). Returns the root element, its
/// name in `root_name`. DOCTYPE is refused.
MarkupNode parseXmlSubset(std::string_view text, std::string_view origin, std::string &root_name);

} // namespace frappe::detail
