// SPDX-License-Identifier: MIT
// TRACE_CONTOUR and GOOD_CANDIDATE: Suzuki border following over the edge
// image, collecting the corner pixels met along each border.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "frappe/edge_map.h"
#include "frappe/image.h"
#include "point_grid.h"

namespace frappe::detail {

/// A quadrilateral found by the tracer, at the traced resolution, corners
/// clockwise on screen starting anywhere.
struct Quad {
	std::array<Point2f, 4> corners;
	/// What a MarkerProbe noted of the quad when it was asked (the detector:
	/// how many border cells read white at the traced outline); -1 when
	/// none. Travels with the quad through sorting and deduplication.
	int probeRead = -1;
	/// With probeRead: the spread of the grey levels it sampled.
	float probeContrast = 0.0f;
	/// With probeRead: the grey level midway between its darkest and
	/// brightest samples (the contrast a region needs follows it).
	float probeLevel = 0.0f;
	/// Where the quad came from: the edge map, or the region map (whose
	/// outline lies up to a region pixel inside the marker's).
	bool fromRegion = false;
	/// From the shade map (EdgeMap::shades; fromRegion too): read after
	/// every other candidate, and only where no marker was read.
	bool fromShade = false;
	/// The probe read it as a marker (and the tracer sealed its inside):
	/// kept first when a frame has more candidates than it may read.
	bool probeDecoded = false;
	/// The probe read a codeword within the detector's max_hamming (a
	/// damaged marker): kept next.
	bool probeNearCode = false;
	/// The probe read a black frame around cells of some contrast: kept
	/// before what it found nothing in (clutter).
	bool probeReadable = false;
};

struct TraceParams {
	float cluster_radius = 4.0f; ///< corner pixels closer than this form one corner
	float min_side = 8.0f;       ///< least mean side (no side under 0.6 of it), traced pixels
	float border_margin = 1.0f;  ///< corners must lie this far inside the frame
	/// Corner clusters a border needs before its outline is fitted: edge
	/// borders without them are mostly clutter; region borders have none.
	int min_clusters = 2;
	/// Longest border kept, as a multiple of its bounding box's perimeter:
	/// a marker's outline goes round its box once; a border that winds
	/// through texture goes many times. Edge borders also double back
	/// along open curves (twice the box), which the later checks reject.
	float max_winding = 1e9f;
	/// Whether the corner pixels (EdgeMap::kCorner) met along a border are
	/// collected: region and shade maps hold none (kEdge alone marks a
	/// pixel), and their walk then skips the test at every step.
	bool corners = true;
	/// Whether hole borders are followed too. Region borders need only the
	/// outer ones: a dark region's outer border is the candidate; the
	/// border of a light hole in it (a marker's white cells, the quiet zone
	/// of a marker on a dark panel) never outlines a marker's dark frame.
	bool holes = true;
};

/// Asked during the scan whether an accepted quad is a marker. Nothing else
/// can lie inside a marker, so the tracer seals its inside before the scan
/// gets there: its code's cells are never followed (on a frame full of
/// markers they are most of the edge pixels), nor is the hole border of its
/// outline, which would be a second candidate for the same marker.
class MarkerProbe
{
public:
	virtual ~MarkerProbe() = default;
	/// May note what it read in quad.probeRead and quad.probeContrast.
	virtual bool isMarker(Quad &quad) = 0;
};

/// Follows every border of the edge image once and keeps those that make a
/// plausible marker outline: four corner clusters, or (with at least
/// `min_clusters` of them) the outline's extreme points, convex, large
/// enough and running along all four sides. Quads may repeat (the inner
/// and outer borders of a ring that no probe sealed): the caller drops the
/// repeats with removeDuplicateQuads().
class ContourTracer
{
public:
	/// Appends the accepted quads to `out` (cleared first). With a probe,
	/// the inside of each quad it calls a marker is skipped.
	void trace(const TraceMap &edges, const TraceParams &params, std::vector<Quad> &out,
		   MarkerProbe *probe = nullptr);

	/// Borders followed in the last call, for statistics.
	int bordersFollowed() const { return borders_; }

	/// Walks borders with the portable C++ loop even where an assembly
	/// one exists (ARMv6): for the tests that compare the two.
	void usePortableWalk(bool on) { portableWalk_ = on; }

private:
	struct Cluster {
		std::int64_t sx, sy; ///< sums of member coordinates
		int n;
		int fx, fy;          ///< first member, the cluster's anchor
	};
	void buildStepTables(int w);
	void follow(int x, int y, int fromDir, const TraceMap &edges, bool corners);
	void followV6(int x, int y, int fromDir, const TraceMap &edges, bool corners); ///< ARMv6 builds only
	void clusterCorners();
	/// The last border's bounding box spans `span` both ways, and its
	/// length is at most maxWinding times the perimeter of the box.
	bool spansAtLeast(float span, float maxWinding) const;
	bool quadFromClusters(Quad &quad) const;
	/// `at`: the indices of the four corners among the border's points.
	bool quadFromOutline(Quad &quad, std::array<std::size_t, 4> &at) const;
	/// With `at` (a quad of outline points: their indices), each side's
	/// coverage is read from its own stretch of the border first.
	bool acceptQuad(const TraceParams &params, int w, int h, Quad &quad,
			const std::array<std::size_t, 4> *at = nullptr);
	void sealInside(const Quad &quad, int w, int h);

	std::vector<std::uint8_t> labels_;
	std::vector<std::uint64_t> startWords_; ///< border starts of a row, a bit a pixel
	/// Column ranges of the runs of occupied tiles, row of tiles after row
	/// of tiles; stretchRows_[ty] is the first of row ty's.
	std::vector<std::pair<int, int>> stretches_;
	std::vector<int> stretchRows_;
	/// Suzuki's step 3.3 for this width, in one of two forms. On 64-bit
	/// targets each edge pixel's eight neighbours are first gathered into
	/// one byte of masks_ (a vectorised pass over the occupied tiles), and
	/// the table is indexed by direction back and that byte, whose entry
	/// says where the next byte is. Elsewhere (the
	/// ARMv6 build, where that pass would cost more than it saves) the
	/// neighbourhood is read from three label rows at every step, and
	/// stepTable_ holds the move's pointer offset, the next direction back
	/// and the label bits to set.
	struct alignas(8) MaskStep { /* 8 bytes: a scaled index addresses it */
		std::int16_t offset; ///< pointer offset of the move
		std::uint8_t back;   ///< direction back from the pixel it reaches
		std::uint8_t mark;   ///< label mark of the pixel it leaves
		std::uint32_t dxy;   ///< the move as x | y << 16 (wrapping)
	};
	bool useMasks_ = false;
	std::vector<std::uint8_t> masks_;
	std::vector<MaskStep> maskTable_;
	std::vector<std::int32_t> stepTable_;
	std::vector<Cluster> clusters_;
	/// The last border's pixels as x | y << 16; only the first steps_ are
	/// valid (follow writes through a local pointer and grows it itself).
	std::vector<std::uint32_t> points_;
	std::vector<std::uint32_t> sampled_; ///< acceptQuad's every stride-th point
	/// The last border's corner pixels, as points_; only the first
	/// cornerCount_ are valid. Clustered only for borders long enough to
	/// be a candidate.
	std::vector<std::uint32_t> corners_;
	int cornerCount_ = 0;
	int steps_ = 0;
	bool tooManyClusters_ = false;
	int borders_ = 0;
	int stride_ = 0;
	bool portableWalk_ = false;
	std::int64_t radius2Floor_ = 16; ///< floor(cluster_radius^2)
};

/// Drops quads whose corners all lie within `tolerance` of an earlier quad's
/// (under some cyclic alignment), keeping the first; in place. The back
/// end's one suppression rule (suppression.h), in time linear in the quads
/// (a frame of thousands of small squares, a tiled wall, has as many).
void removeDuplicateQuads(std::vector<Quad> &quads, float tolerance, PointGrid &grid);
/// The same with a grid of its own, which it allocates: for tests.
void removeDuplicateQuads(std::vector<Quad> &quads, float tolerance);

/// Keeps at most `most` of `quads`, in their order, ranked by what the
/// probe found: markers (probeDecoded), then near codes (probeNearCode),
/// then readable frames (probeReadable), then the rest; within a rank from
/// the front. Returns how many it dropped. In place, linear; allocates
/// nothing.
int capCandidates(std::vector<Quad> &quads, int most);

} // namespace frappe::detail
