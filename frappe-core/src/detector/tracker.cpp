// SPDX-License-Identifier: MIT
// Mode::Track: the regions a frame's front end reads and the tracks that
// predict them (tracker.h).
#include "tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

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
			for (int y = ya; y < yb; ++y) {
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

RegionFrontEnd::RegionFrontEnd(const BandKernels &kernels) : cpu_(makeCpuFrontEnd(1, kernels))
{
	written_.reserve(64);
}

PixelRect RegionFrontEnd::alignedRect(PixelRect r, int width, int height)
{
	r.x0 = std::clamp(alignDown(std::max(0, r.x0), kAlign), 0, width);
	r.y0 = std::clamp(alignDown(std::max(0, r.y0), kAlign), 0, height);
	r.x1 = std::clamp(alignUp(std::max(0, r.x1), kAlign), 0, width);
	r.y1 = std::clamp(alignUp(std::max(0, r.y1), kAlign), 0, height);
	return r;
}

void RegionFrontEnd::run(const ImageView &image, std::span<const PixelRect> rects, const FrontEndParams &params,
			 EdgeMap &out)
{
	const int w = image.width, h = image.height;
	const bool sameSize = out.width == w && out.height == h && out.scale == 1.0f;
	out.resize(w, h);
	out.scale = 1.0f;
	if (dirtyAll_ || !sameSize || last_ != &out) {
		std::fill(out.pixels.begin(), out.pixels.end(), 0);
	} else {
		/* Only what the last run wrote. */
		for (const PixelRect &r : written_)
			clearRect(out, r.x0, r.y0, r.x1, r.y1);
	}
	std::fill(out.tiles.begin(), out.tiles.end(), 0);
	dirtyAll_ = false;
	last_ = &out;
	written_.clear();
	bytesRead_ = 0;
	/* The edge maps of the rectangles: their region maps are not made
	 * (the whole frame's is, below). */
	FrontEndParams edgesOnly = params;
	edgesOnly.region_contrast = 0;
	constexpr int T = TraceMap::kTile;
	for (PixelRect r : rects) {
		r = alignedRect(r, w, h);
		if (r.empty())
			continue;
		/* The part read starts on a tile, so that the sub map's tiles
		 * are the frame's. */
		const PixelRect s{ std::max(0, alignDown(r.x0 - kMargin, T)), std::max(0, alignDown(r.y0 - kMargin, T)),
				   std::min(w, r.x1 + kMargin), std::min(h, r.y1 + kMargin) };
		const ImageView sub(image.row(s.y0) + s.x0, s.x1 - s.x0, s.y1 - s.y0, image.stride);
		cpu_->run(sub, 1.0f, edgesOnly, sub_);
		bytesRead_ += s.area();
		copyRect(sub_, s.x0, s.y0, out, r.x0, r.y0, r.x1, r.y1);
		markRectTiles(&sub_, s.x0, s.y0, out, r.x0, r.y0, r.x1, r.y1);
		written_.push_back(r);
	}
	/* The region and shade maps of the whole frame, exactly a whole run's:
	 * at half resolution they cost a fraction of the edges, and they are
	 * the search for new markers between the bands (a marker on a band's
	 * seam, one that enters the frame) as well as the blur and light
	 * paths of the rectangles. One read of every pixel. */
	regionMap(image, 1.0f, params, out.regions, out.shades, scratch_);
	if (out.regions.width > 0)
		bytesRead_ += static_cast<std::size_t>(w) * h;
	keepOnlyRects(out.shades);
}

/* The shade map outside the rectangles is cleared: the lighting path for
 * the markers the rectangles hold (the tracked ones, the band's), while
 * the region map searches the rest of the frame. Traced whole, its
 * clutter cost as much as the region map's. */
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
	std::fill(m.tiles.begin(), m.tiles.end(), 0);
	for (const PixelRect &r : written_)
		markRectTiles(nullptr, 0, 0, m, r.x0 / 2, r.y0 / 2, std::min(m.width, r.x1 / 2), std::min(m.height, r.y1 / 2));
}

Tracker::Tracker(int coverFrames) : coverFrames_(std::max(1, coverFrames))
{
	tracks_.reserve(64);
	next_.reserve(64);
	predictions_.reserve(64);
	regions_.reserve(64);
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
	 * boundaries move by half a band every other round, so that a marker
	 * on the seam of two bands in one round is inside one in the next; the
	 * bands overlap by kAlign rows either way. */
	const int k = coverFrames_;
	const int band = sinceWhole_ % k;
	const int shift = (sinceWhole_ / k) % 2 ? h / (2 * k) : 0;
	++sinceWhole_;
	auto boundary = [&](int i) {
		if (i <= 0)
			return 0;
		if (i >= k)
			return h;
		return std::clamp(static_cast<int>(static_cast<long long>(h) * i / k) + shift, 0, h);
	};
	regions_.push_back(RegionFrontEnd::alignedRect(
		{ 0, boundary(band) - RegionFrontEnd::kAlign, w, boundary(band + 1) + RegionFrontEnd::kAlign }, w, h));
	mergeRects(regions_);
	std::size_t area = 0;
	for (const PixelRect &r : regions_)
		area += r.area();
	/* Regions over most of the frame: the whole frame costs less (no
	 * margins read twice, nothing copied). */
	if (area * 10 > static_cast<std::size_t>(w) * h * 7) {
		regions_.clear();
		return false;
	}
	return true;
}

void Tracker::runRegions(const ImageView &image, const FrontEndParams &params, EdgeMap &out)
{
	regionFrontEnd_.run(image, regions_, params, out);
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
