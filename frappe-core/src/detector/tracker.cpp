// SPDX-License-Identifier: MIT
// Mode::Track: the regions a frame's front end reads and the tracks that
// predict them (tracker.h).
#include "tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "quad_geometry.h"
#include "region_map.h"

namespace frappe::detail {

namespace {

int alignDown(int v, int a) { return v / a * a; }
int alignUp(int v, int a) { return (v + a - 1) / a * a; }

/* Copies rows [y0, y1) x columns [x0, x1) of a map at (sx, sy) into the
 * same pixels of a map of the whole frame. */
void copyRect(const TraceMap &sub, int sx, int sy, TraceMap &out, int x0, int y0, int x1, int y1)
{
	if (x1 <= x0)
		return;
	for (int y = y0; y < y1; ++y)
		std::memcpy(out.pixels.data() + static_cast<std::size_t>(y) * out.width + x0,
			    sub.pixels.data() + static_cast<std::size_t>(y - sy) * sub.width + (x0 - sx),
			    static_cast<std::size_t>(x1 - x0));
}

/* Marks the tiles of `out` that [x0, x1) x [y0, y1) puts a pixel in, the
 * rectangle copied from `sub` (or nullptr), whose tile grid is the frame's
 * shifted by (sx, sy), multiples of the tile. A tile wholly inside takes
 * the sub map's; one the rectangle cuts (two may share it) is read, a word
 * at a time. */
void markRectTiles(const TraceMap *sub, int sx, int sy, TraceMap &out, int x0, int y0, int x1, int y1)
{
	constexpr int T = TraceMap::kTile;
	for (int ty = y0 / T; ty * T < y1; ++ty) {
		const int ya = std::max(y0, ty * T), yb = std::min(y1, ty * T + T);
		const bool rowsWhole = ya == ty * T && (yb == ty * T + T || yb == out.height);
		std::uint8_t *tiles = out.tiles.data() + static_cast<std::size_t>(ty) * out.tiles_x;
		const std::uint8_t *subTiles =
			sub ? sub->tiles.data() + static_cast<std::size_t>(ty - sy / T) * sub->tiles_x : nullptr;
		for (int tx = x0 / T; tx * T < x1; ++tx) {
			if (tiles[tx])
				continue;
			const int a = std::max(x0, tx * T), b = std::min(x1, tx * T + T);
			if (sub && rowsWhole && a == tx * T && (b == tx * T + T || b == out.width)) {
				tiles[tx] = subTiles[tx - sx / T];
				continue;
			}
			std::uint64_t any = 0;
			for (int y = ya; y < yb && !any; ++y) {
				const std::uint8_t *p = out.pixels.data() + static_cast<std::size_t>(y) * out.width;
				int x = a;
				for (; x + 8 <= b; x += 8) {
					std::uint64_t v;
					std::memcpy(&v, p + x, 8);
					any |= v;
				}
				for (; x < b; ++x)
					any |= p[x];
			}
			tiles[tx] = any != 0;
		}
	}
}

void clearRect(TraceMap &m, int x0, int y0, int x1, int y1)
{
	x1 = std::min(x1, m.width);
	y1 = std::min(y1, m.height);
	if (x1 <= x0)
		return;
	for (int y = y0; y < y1; ++y)
		std::memset(m.pixels.data() + static_cast<std::size_t>(y) * m.width + x0, 0,
			    static_cast<std::size_t>(x1 - x0));
}

/* Merges two rectangles where their union is no larger than both: fewer
 * pixels read twice. Others may overlap: each writes the same bytes where
 * they do, so a marker on the seam of two is whole in the maps. */
void mergeRects(std::vector<PixelRect> &rects)
{
	for (bool merged = true; merged;) {
		merged = false;
		for (std::size_t i = 0; i < rects.size() && !merged; ++i)
			for (std::size_t j = i + 1; j < rects.size(); ++j) {
				PixelRect &a = rects[i];
				const PixelRect &b = rects[j];
				const PixelRect u{ std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1),
						   std::max(a.y1, b.y1) };
				if (u.area() > a.area() + b.area())
					continue;
				a = u;
				rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(j));
				merged = true;
				break;
			}
	}
}

float side(const std::array<Point2f, 4> &c)
{
	float s = 0.0f;
	for (int i = 0; i < 4; ++i)
		s += std::hypot(c[(i + 1) % 4].x - c[i].x, c[(i + 1) % 4].y - c[i].y);
	return s / 4.0f;
}

Point2f centre(const std::array<Point2f, 4> &c)
{
	return { (c[0].x + c[1].x + c[2].x + c[3].x) / 4.0f, (c[0].y + c[1].y + c[2].y + c[3].y) / 4.0f };
}

bool insideFrame(const std::array<Point2f, 4> &c, int width, int height, float margin)
{
	for (const Point2f &p : c)
		if (!(p.x >= margin && p.y >= margin && p.x <= width - 1 - margin && p.y <= height - 1 - margin))
			return false;
	return true;
}

} // namespace

namespace {

/* Clears the pixels of `m` whose centres lie inside the convex quad `q`
 * (in m's coordinates): each row's span between the sides it crosses.
 * Nothing to do where the tiles under its box are empty (most of a frame
 * the front end did not read). */
void clearQuad(TraceMap &m, const std::array<Point2f, 4> &q)
{
	const QuadBox box = quadBox(q);
	const int y0 = std::max(0, static_cast<int>(std::ceil(box.y0 - 0.5f)));
	const int y1 = std::min(m.height - 1, static_cast<int>(std::floor(box.y1 - 0.5f)));
	const int bx0 = std::max(0, static_cast<int>(std::floor(box.x0)));
	const int bx1 = std::min(m.width - 1, static_cast<int>(std::ceil(box.x1)));
	if (y1 < y0 || bx1 < bx0)
		return;
	constexpr int T = TraceMap::kTile;
	bool any = false;
	for (int ty = y0 / T; ty <= y1 / T && !any; ++ty)
		for (int tx = bx0 / T; tx <= bx1 / T && !any; ++tx)
			any = !m.tileEmpty(tx, ty);
	if (!any)
		return;
	const QuadSpans rows(q, true);
	for (int y = y0; y <= y1; ++y) {
		float left, right;
		if (!rows.span(static_cast<float>(y) + 0.5f, left, right))
			continue;
		const int x0 = std::max(0, static_cast<int>(std::ceil(left - 0.5f)));
		const int x1 = std::min(m.width - 1, static_cast<int>(std::floor(right - 0.5f)));
		if (x1 >= x0)
			std::memset(m.pixels.data() + static_cast<std::size_t>(y) * m.width + x0, 0,
				    static_cast<std::size_t>(x1 - x0 + 1));
	}
}

} // namespace

void clearInsideMarkers(EdgeMap &maps, std::span<const Marker> markers, float inset)
{
	for (const Marker &mk : markers) {
		const Point2f c = centre(mk.corners);
		for (TraceMap *m : { static_cast<TraceMap *>(&maps), &maps.regions, &maps.shades }) {
			if (m->width == 0)
				continue;
			/* Each corner `inset` nearer the centre, in m's pixels. */
			std::array<Point2f, 4> q;
			for (int i = 0; i < 4; ++i) {
				const float dx = mk.corners[i].x - c.x, dy = mk.corners[i].y - c.y;
				const float r = std::hypot(dx, dy);
				const float k = r > inset ? (r - inset) / r : 0.0f;
				q[i] = { (c.x + dx * k) * m->scale, (c.y + dy * k) * m->scale };
			}
			clearQuad(*m, q);
		}
	}
}

RegionFrontEnd::RegionFrontEnd(const BandKernels &kernels) : cpu_(makeCpuFrontEnd(1, kernels))
{
	written_.reserve(64);
	halfWritten_.reserve(72);
}

PixelRect RegionFrontEnd::alignedRect(PixelRect r, int width, int height)
{
	r.x0 = std::clamp(alignDown(std::max(0, r.x0), kAlign), 0, width);
	r.y0 = std::clamp(alignDown(std::max(0, r.y0), kAlign), 0, height);
	r.x1 = std::clamp(alignUp(std::max(0, r.x1), kAlign), 0, width);
	r.y1 = std::clamp(alignUp(std::max(0, r.y1), kAlign), 0, height);
	return r;
}

/* Copies the half-resolution map `sub`, made from the frame's pixels from
 * (sx, sy) on, into `out` over the half-resolution pixels of frame
 * rectangle r. */
void copyHalf(const TraceMap &sub, int sx, int sy, TraceMap &out, const PixelRect &r)
{
	if (sub.width == 0 || out.width == 0)
		return;
	const int x1 = std::min({ r.x1 / 2, out.width, sx / 2 + sub.width });
	const int y1 = std::min({ r.y1 / 2, out.height, sy / 2 + sub.height });
	copyRect(sub, sx / 2, sy / 2, out, r.x0 / 2, r.y0 / 2, x1, y1);
}

void RegionFrontEnd::run(const ImageView &image, std::span<const PixelRect> rects, std::span<const PixelRect> search,
			 const FrontEndParams &params, EdgeMap &out)
{
	const int w = image.width, h = image.height;
	const bool sameSize = out.width == w && out.height == h && out.scale == 1.0f;
	const bool clearAll = dirtyAll_ || !sameSize || last_ != &out;
	out.resize(w, h);
	out.scale = 1.0f;
	if (clearAll) {
		std::fill(out.pixels.begin(), out.pixels.end(), 0);
		/* A strip's maps at most the frame's: sized once, whatever
		 * strips come. */
		const std::size_t half = static_cast<std::size_t>(w / 2 + TraceMap::kTile) * (h / 2 + TraceMap::kTile);
		for (TraceMap *m : { &subRegions_, &subShades_ }) {
			m->pixels.reserve(half);
			m->tiles.reserve(half / (TraceMap::kTile * TraceMap::kTile) + w + h);
		}
	} else {
		/* Only what the last run wrote. */
		for (const PixelRect &r : written_)
			clearRect(out, r.x0, r.y0, r.x1, r.y1);
	}
	std::fill(out.tiles.begin(), out.tiles.end(), 0);
	bool whole = false;
	for (PixelRect r : search) {
		r = alignedRect(r, w, h);
		whole = whole || (r.x0 == 0 && r.y0 == 0 && r.x1 == w && r.y1 == h);
	}
	/* The region and shade maps, half resolution: the whole frame's, or
	 * zero but where the rectangles and the search strips put theirs. */
	const bool regions = makesRegionMap(w, h, params.region_contrast);
	if (!whole) {
		for (TraceMap *m : { &out.regions, &out.shades }) {
			const bool made = regions && (m == &out.regions || params.makesShades());
			const bool same = m->width == (made ? w / 2 : 0) && m->height == (made ? h / 2 : 0);
			m->resize(made ? w / 2 : 0, made ? h / 2 : 0);
			m->scale = 0.5f;
			if (clearAll || !same || halfWhole_) {
				std::fill(m->pixels.begin(), m->pixels.end(), 0);
			} else {
				for (const PixelRect &r : halfWritten_)
					clearRect(*m, r.x0 / 2, r.y0 / 2, r.x1 / 2, r.y1 / 2);
			}
		}
	}
	dirtyAll_ = false;
	last_ = &out;
	halfWhole_ = whole;
	written_.clear();
	halfWritten_.clear();
	bytesRead_ = 0;
	/* The rectangles' edges, with their region and shade maps unless the
	 * whole frame's are made below. */
	FrontEndParams rectParams = params;
	if (whole)
		rectParams.region_contrast = 0;
	constexpr int T = TraceMap::kTile;
	/* Each part (aligned, not empty) with the pixels it reads: its
	 * margin, from a tile's start, so that the sub map's tiles are the
	 * frame's. */
	auto eachPart = [&](std::span<const PixelRect> parts, auto &&use) {
		for (PixelRect r : parts) {
			r = alignedRect(r, w, h);
			if (r.empty())
				continue;
			const PixelRect s{ std::max(0, alignDown(r.x0 - kMargin, T)),
					   std::max(0, alignDown(r.y0 - kMargin, T)), std::min(w, r.x1 + kMargin),
					   std::min(h, r.y1 + kMargin) };
			bytesRead_ += s.area();
			use(r, s, ImageView(image.row(s.y0) + s.x0, s.x1 - s.x0, s.y1 - s.y0, image.stride));
		}
	};
	eachPart(rects, [&](const PixelRect &r, const PixelRect &s, const ImageView &sub) {
		cpu_->run(sub, 1.0f, rectParams, sub_);
		copyRect(sub_, s.x0, s.y0, out, r.x0, r.y0, r.x1, r.y1);
		markRectTiles(&sub_, s.x0, s.y0, out, r.x0, r.y0, r.x1, r.y1);
		if (!whole) {
			copyHalf(sub_.regions, s.x0, s.y0, out.regions, r);
			copyHalf(sub_.shades, s.x0, s.y0, out.shades, r);
		}
		written_.push_back(r);
	});
	if (whole) {
		/* The whole frame's region map, one read of every pixel; the
		 * shade map kept in the rectangles. */
		regionMap(image, 1.0f, params, out.regions, out.shades, scratch_);
		if (out.regions.width > 0)
			bytesRead_ += static_cast<std::size_t>(w) * h;
		keepOnlyRects(out.shades);
		return;
	}
	halfWritten_ = written_;
	if (!regions)
		return;
	/* The search strips: the region map only (a shade map would be
	 * dropped). */
	eachPart(search, [&](const PixelRect &r, const PixelRect &s, const ImageView &sub) {
		regionMap(sub, 1.0f, params, subRegions_, subShades_, scratch_, false);
		copyHalf(subRegions_, s.x0, s.y0, out.regions, r);
		halfWritten_.push_back(r);
	});
	markHalfTiles(out.regions, halfWritten_);
	markHalfTiles(out.shades, written_);
}

/* The tiles of a half-resolution map that the rectangles put a pixel in
 * (nothing is set outside them). */
void RegionFrontEnd::markHalfTiles(TraceMap &m, std::span<const PixelRect> rects)
{
	if (m.width == 0)
		return;
	std::fill(m.tiles.begin(), m.tiles.end(), 0);
	for (const PixelRect &r : rects)
		markRectTiles(nullptr, 0, 0, m, r.x0 / 2, r.y0 / 2, std::min(m.width, r.x1 / 2),
			      std::min(m.height, r.y1 / 2));
}

/* The shade map outside the rectangles is cleared: the lighting path for
 * the markers the rectangles hold (the tracks' that did not read at their
 * prediction, the band's). Traced whole, its clutter cost as much as the
 * region map's. */
void RegionFrontEnd::keepOnlyRects(TraceMap &m)
{
	if (m.width == 0)
		return;
	row_.resize(static_cast<std::size_t>(m.width));
	for (int y = 0; y < m.height; ++y) {
		std::uint8_t *p = m.pixels.data() + static_cast<std::size_t>(y) * m.width;
		std::fill(row_.begin(), row_.end(), 0);
		bool any = false;
		for (const PixelRect &r : written_) {
			if (2 * y < r.y0 || 2 * y >= r.y1)
				continue;
			const int x0 = r.x0 / 2, x1 = std::min(m.width, r.x1 / 2);
			std::copy(p + x0, p + x1, row_.begin() + x0);
			any = true;
		}
		if (any)
			std::copy(row_.begin(), row_.end(), p);
		else
			std::fill_n(p, m.width, 0);
	}
	markHalfTiles(m, written_);
}

Tracker::Tracker(int coverFrames) : coverFrames_(std::max(1, coverFrames))
{
	tracks_.reserve(64);
	next_.reserve(64);
	predictions_.reserve(64);
	regions_.reserve(64);
	strips_.reserve(8); /* placeStrips()'s, the gaps to the band, the band */
	matched_.reserve(64);
}

void Tracker::reset()
{
	std::lock_guard<std::mutex> guard(lock_);
	tracks_.clear();
	haveSamples_ = false;
	wholeNext_ = true;
	sinceWhole_ = 0;
	regionFrontEnd_.invalidate();
}

bool Tracker::sceneChanged(const ImageView &image)
{
	long long diff = 0;
	for (int j = 0; j < kSamplesY; ++j) {
		const std::uint8_t *row = image.row(static_cast<int>((2LL * j + 1) * image.height / (2 * kSamplesY)));
		for (int i = 0; i < kSamplesX; ++i) {
			const std::uint8_t v = row[(2LL * i + 1) * image.width / (2 * kSamplesX)];
			std::uint8_t &s = samples_[static_cast<std::size_t>(j) * kSamplesX + i];
			diff += std::abs(static_cast<int>(v) - s);
			s = v;
		}
	}
	const bool changed = haveSamples_ && diff > static_cast<long long>(kSceneChange) * kSamplesX * kSamplesY;
	haveSamples_ = true;
	return changed;
}

std::array<Point2f, 4> Tracker::predict(const Track &t) const
{
	if (!t.moving)
		return t.now;
	std::array<Point2f, 4> p;
	for (int i = 0; i < 4; ++i)
		p[i] = { 2.0f * t.now[i].x - t.before[i].x, 2.0f * t.now[i].y - t.before[i].y };
	return p;
}

bool Tracker::plan(const ImageView &image, bool regionsPossible)
{
	std::lock_guard<std::mutex> guard(lock_);
	const int w = image.width, h = image.height;
	const bool newSize = w != width_ || h != height_;
	width_ = w;
	height_ = h;
	const bool changed = sceneChanged(image);
	regions_.clear();
	predictions_.clear();
	{
		Point2f v{ 0.0f, 0.0f };
		int n = 0;
		for (const Track &t : tracks_)
			if (t.moving && t.missed == 0) {
				v.x += centre(t.now).x - centre(t.before).x;
				v.y += centre(t.now).y - centre(t.before).y;
				++n;
			}
		haveMotion_ = n > 0;
		motion_ = n > 0 ? Point2f{ v.x / n, v.y / n } : Point2f{ 0.0f, 0.0f };
	}
	/* Too small a frame for regions to pay: its margins are most of it. */
	const bool small = w < 4 * RegionFrontEnd::kAlign || h < 4 * RegionFrontEnd::kAlign;
	if (!regionsPossible || newSize || changed || wholeNext_ || small || coverFrames_ <= 1) {
		wholeNext_ = false;
		sinceWhole_ = 0;
		return false;
	}
	for (const Track &t : tracks_) {
		const std::array<Point2f, 4> p = predict(t);
		float x0 = p[0].x, x1 = p[0].x, y0 = p[0].y, y1 = p[0].y;
		for (int i = 0; i < 4; ++i)
			for (const Point2f &q : { p[i], t.now[i] }) {
				x0 = std::min(x0, q.x);
				x1 = std::max(x1, q.x);
				y0 = std::min(y0, q.y);
				y1 = std::max(y1, q.y);
			}
		/* Room for the outline's edges and a change of speed: the maps
		 * need only hold the outline (refinement, the probe and the
		 * checks of the quiet zone read the frame itself). A marker
		 * that leaves its region is found by a whole search. */
		const float speed = std::hypot(centre(p).x - centre(t.now).x, centre(p).y - centre(t.now).y);
		const float m = std::max(kMinRoom, kRoom * side(t.now)) + 0.5f * speed;
		predictions_.push_back(
			{ t.id, p,
			  RegionFrontEnd::alignedRect(
				  { static_cast<int>(std::floor(x0 - m)), static_cast<int>(std::floor(y0 - m)),
				    static_cast<int>(std::ceil(x1 + m)) + 1, static_cast<int>(std::ceil(y1 + m)) + 1 },
				  w, h) });
	}
	return true;
}

bool Tracker::placeRegions(std::span<const std::uint8_t> read)
{
	std::lock_guard<std::mutex> guard(lock_);
	const int w = width_, h = height_;
	regions_.clear();
	for (std::size_t i = 0; i < predictions_.size(); ++i)
		if (i >= read.size() || !read[i])
			regions_.push_back(predictions_[i].rect);
	/* One band of rows of the k, all of the frame every k frames. Its
	 * boundaries move by a third of a band every round, through three
	 * places, so that a marker on the seam of two bands in one round is
	 * inside one in the next, and so are the full-path rounds' (every
	 * other one: they too go through all three); the bands overlap by
	 * kAlign rows either way. The region map
	 * searches the band on every round, the edges and the shade map on
	 * one round of kFullBandRounds: a new marker is in the region map
	 * within k frames (the strips and the band find most of them there)
	 * and in every map within kFullBandRounds k, at a fraction of the
	 * front end's and the trace's cost on the other rounds. */
	const int k = coverFrames_;
	const int round = sinceWhole_ / k;
	const int band = sinceWhole_ % k;
	const bool fullBand = round % kFullBandRounds == 0;
	const int shift = static_cast<int>(static_cast<long long>(h) * (round % 3) / (3 * k));
	++sinceWhole_;
	auto boundary = [&](int i) {
		if (i <= 0)
			return 0;
		if (i >= k)
			return h;
		return std::clamp(static_cast<int>(static_cast<long long>(h) * i / k) + shift, 0, h);
	};
	const PixelRect bandRect = RegionFrontEnd::alignedRect(
		{ 0, boundary(band) - RegionFrontEnd::kAlign, w, boundary(band + 1) + RegionFrontEnd::kAlign }, w, h);
	if (fullBand)
		regions_.push_back(bandRect);
	mergeRects(regions_);
	placeStrips();
	if (!(strips_.size() == 1 && strips_[0] == PixelRect{ 0, 0, w, h })) {
		/* A marker entering over the top or bottom edge may be taller
		 * than the strip there: the rows between the strip and a band
		 * less than a band away join them in the region map, so that it
		 * is whole there on that band's frame of each round. */
		const std::size_t n = strips_.size();
		for (std::size_t i = 0; i < n; ++i) {
			const PixelRect st = strips_[i];
			if (st.x0 != 0 || st.x1 != w)
				continue;
			if (st.y0 > bandRect.y1 && st.y0 - bandRect.y1 < h / k)
				strips_.push_back({ 0, bandRect.y1, w, st.y0 });
			if (st.y1 < bandRect.y0 && bandRect.y0 - st.y1 < h / k)
				strips_.push_back({ 0, st.y1, w, bandRect.y0 });
		}
		/* The region map's band. */
		if (!fullBand)
			strips_.push_back(bandRect);
	}
	std::size_t area = 0;
	for (const PixelRect &r : regions_)
		area += r.area();
	/* Regions over most of the frame: the whole frame costs less (no
	 * margins read twice, nothing copied). */
	if (area * 10 > static_cast<std::size_t>(w) * h * 7) {
		regions_.clear();
		strips_.clear();
		return false;
	}
	return true;
}

/* Where a marker can enter the frame on this one: the region map over
 * strips along the frame's edges, on the sides the tracks' mean motion
 * brings new content in from, as wide as kStrip of the frame's larger side
 * plus twice that motion; none on a still scene. Markers that appear
 * elsewhere (nearer, sharper, uncovered) are the band's. With no moving
 * track (none yet, or a frame in flight in a Pipeline), the whole
 * frame's region map. */
void Tracker::placeStrips()
{
	const int w = width_, h = height_;
	strips_.clear();
	if (!haveMotion_) {
		strips_.push_back({ 0, 0, w, h });
		return;
	}
	const float b = kStrip * static_cast<float>(std::max(w, h));
	const int bx = static_cast<int>(b + 2.0f * std::abs(motion_.x));
	const int by = static_cast<int>(b + 2.0f * std::abs(motion_.y));
	if (motion_.x > kStill)
		strips_.push_back({ 0, 0, bx, h });
	if (motion_.x < -kStill)
		strips_.push_back({ w - bx, 0, w, h });
	if (motion_.y > kStill)
		strips_.push_back({ 0, 0, w, by });
	if (motion_.y < -kStill)
		strips_.push_back({ 0, h - by, w, h });
}

void Tracker::runRegions(const ImageView &image, const FrontEndParams &params, EdgeMap &out)
{
	regionFrontEnd_.run(image, regions_, strips_, params, out);
}

bool Tracker::update(std::vector<Marker> &markers, int width, int height, bool partial, bool mayRetry)
{
	std::lock_guard<std::mutex> guard(lock_);
	retry_ = false;
	/* Each marker to the nearest prediction of its id, within about a
	 * side: each track continues at most one marker. */
	matched_.assign(tracks_.size(), -1);
	for (std::size_t mi = 0; mi < markers.size(); ++mi) {
		Marker &m = markers[mi];
		const Point2f c = centre(m.corners);
		const float reach = std::max(16.0f, side(m.corners));
		int best = -1;
		float bestDist = reach;
		for (std::size_t ti = 0; ti < tracks_.size(); ++ti) {
			if (tracks_[ti].id != m.id || matched_[ti] >= 0)
				continue;
			const Point2f p = centre(predict(tracks_[ti]));
			const float d = std::hypot(p.x - c.x, p.y - c.y);
			if (d < bestDist) {
				bestDist = d;
				best = static_cast<int>(ti);
			}
		}
		if (best >= 0)
			matched_[best] = static_cast<int>(mi);
		m.tracked = best >= 0;
	}
	/* A marker found on the last frame and predicted wholly inside this
	 * one, yet not found in its region: it moved further than predicted,
	 * or the region missed it. The whole frame finds it, at once when the
	 * caller can search this frame again, else on the next. */
	bool lost = false;
	for (std::size_t ti = 0; ti < tracks_.size(); ++ti)
		if (matched_[ti] < 0 && tracks_[ti].missed == 0 && insideFrame(predict(tracks_[ti]), width, height, 2.0f))
			lost = true;
	if (lost && partial && mayRetry) {
		wholeNext_ = true;
		retry_ = true;
		return true;
	}
	if (lost && partial)
		wholeNext_ = true;
	next_.clear();
	for (std::size_t mi = 0; mi < markers.size(); ++mi) {
		Track t;
		t.id = markers[mi].id;
		t.now = markers[mi].corners;
		next_.push_back(t);
	}
	for (std::size_t ti = 0; ti < tracks_.size(); ++ti) {
		const Track &old = tracks_[ti];
		if (matched_[ti] >= 0) {
			/* matched_ indexes markers, which next_ lists first, in order. */
			Track &t = next_[static_cast<std::size_t>(matched_[ti])];
			t.before = old.now;
			t.moving = true;
		} else if (old.missed < kKeepMissed) {
			/* Kept a few frames on its prediction, its region still
			 * searched: a marker a frame or two too blurred to read is
			 * found again as tracked. */
			Track t = old;
			t.now = predict(old);
			t.before = old.now;
			++t.missed;
			if (insideFrame(t.now, width, height, -side(t.now)))
				next_.push_back(t);
		}
	}
	std::swap(tracks_, next_);
	return false;
}

} // namespace frappe::detail
