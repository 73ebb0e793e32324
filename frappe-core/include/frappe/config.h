// SPDX-License-Identifier: MIT
// frappe/config.h: every parameter of the detector, in one place.
#pragma once

#include <memory>
#include <string>

#include "frappe/dictionary.h"

namespace frappe {

/// How the detector chooses the resolution it searches at.
enum class Mode {
	/// Every frame at full resolution (the paper's NORMAL).
	Normal,
	/// Scale the next frame down so that the smallest marker of the previous
	/// frame is about `scaled_size` pixels wide (the paper's ASCALE). Faster
	/// on video with large markers, at the price of missing small markers that
	/// appear while scaled; every `max_scaled_frames` frames one is at full size.
	AScale,
	/// Video: the markers of the last frames predict where each will be (a
	/// constant-velocity model of its corners); each is read where
	/// predicted, its corners measured on the frame, and the full detector
	/// runs in a region around those that are not. The rest of the frame
	/// is searched for new markers a band of rows at a time: by the region
	/// map (half resolution) all of it at least every `track_cover_frames`
	/// frames, and by every path (edges, the shade map) every other round,
	/// all of it every 2 `track_cover_frames`; the region map also searches
	/// strips along the edges where the scene's motion brings markers in.
	/// All of it at once after a scene change or when a tracked marker is
	/// not found where predicted (then the same frame is searched again,
	/// whole). Marker::tracked says which markers were tracked; corners are
	/// always measured on the frame. About a third of NORMAL's median
	/// instructions a frame on the synthetic sequences, the same markers
	/// found (docs/tracking.md). Needs a front end that can run on regions
	/// (the CPU's); others run every frame whole. One detector per video,
	/// its frames in order (a Pipeline's Overlap::Frames on several threads
	/// gives each detector a part of them; Overlap::Stages keeps one).
	Track,
};

/// Detector parameters. Defaults are the paper's Table 1. Each field says what
/// it trades off. Parameters hold no state: the Detector owns what lives
/// across frames.
struct Config {
	/// Marker family, a name from dictionaryNames() ("aruco_mip_36h12",
	/// "apriltag_36h11", "6x6_250", ...).
	std::string dictionary = "aruco_mip_36h12";
	/// A dictionary of the user's own (loadDictionary()): when set, it is
	/// used and `dictionary` is ignored. Shared, never copied: a Detector
	/// keeps it alive.
	std::shared_ptr<const Dictionary> custom_dictionary;

	Mode mode = Mode::Normal;

	/// e_thr: Sobel gradient magnitude, for intensities in [0, 1], that an
	/// edge pixel must exceed after non-maximum suppression. Lower finds
	/// fainter and blurrier markers but feeds the contour tracer (the most
	/// expensive stage) more clutter. Range (0, 4].
	float edge_threshold = 0.27f;

	/// c_thr: Shi-Tomasi minimum eigenvalue of the 3x3 structure tensor
	/// (summed, same units as edge_threshold squared) that marks an edge pixel
	/// as a corner. Too high loses the corners of low-contrast or blurred
	/// markers; too low splits one corner into several clusters.
	float corner_threshold = 0.19f;

	/// h_thr: the most bit errors corrected when decoding, among cells read
	/// clearly. -1 takes the dictionary's careful default,
	/// Dictionary::defaultMaxHamming() (0 for 4x4 families, 2 for
	/// aruco_mip_36h12). Higher finds damaged markers but raises the chance
	/// of a wrong id. Range -1 .. bits^2 / 2.
	int max_hamming = -1;

	/// A code cell whose mean lies closer to the threshold than this
	/// fraction of half the black-white contrast is a weak read: blur and
	/// small cells put true errors there, chance puts them anywhere. Weak
	/// cells may be corrected beyond max_hamming, up to
	/// Dictionary::weakMaxHamming() bits in all. Higher finds more blurred
	/// and small markers at a higher chance of a wrong id; 0 corrects only
	/// max_hamming bits of any kind. Range [0, 1].
	float weak_margin = 0.3f;

	/// beta (AScale only): target side in pixels of the smallest marker after
	/// scaling. Smaller scales more aggressively (faster) but loses markers
	/// whose cells fall below about 3 pixels.
	float scaled_size = 28.0f;

	/// n_max_scaled (AScale only): at most this many scaled frames in a row
	/// before one at full resolution, so small new markers are seen.
	int max_scaled_frames = 5;

	/// k (Track only): every part of the frame is searched for new markers
	/// by the region map at least once every this many frames, a band of
	/// rows at a time, and by every path every 2k. A marker that enters the
	/// scene and shows in the region map is found at most k - 1 frames
	/// after the frame it is first whole in. The default, 4, finds it within
	/// 100 ms at 30 frames a second; lower finds it sooner at a higher
	/// cost a frame, 1 searches every frame whole (Normal's cost, with
	/// Marker::tracked). Range [1, 1000].
	int track_cover_frames = 4;

	/// The second source of candidates, for blurred markers: dark regions
	/// of the frame at half resolution, whose borders stay closed where blur
	/// opens the edge ring. A pixel is dark when it lies below the midpoint
	/// of the darkest and brightest pixels within about 12 px and those
	/// differ by at least this much (intensities in [0, 1]). Lower finds
	/// fainter blurred markers but traces more clutter; 0 turns the region
	/// candidates off (the paper's edge candidates only: faster, and blind
	/// to strongly blurred markers). Range [0, 1].
	float region_contrast = 0.16f;

	/// Dim light: below mid-grey the edge, corner and region thresholds
	/// scale with the local brightness plus this floor (intensities in
	/// [0, 1]), so that a marker in a dim room, under a blind's shadow or
	/// a cast shadow keeps the edges and the dark region it has in full
	/// light (the exact rule: front_end_cpu.cpp). The floor keeps sensor
	/// noise in the darkest pixels from making edges: lower finds markers
	/// in darker scenes at the price of more clutter traced there; 0.5 or
	/// more keeps every threshold absolute (the paper's). With
	/// light_floor_noise it is the ceiling: a frame's floor lies between
	/// half of it and it. Range [0, 1].
	float light_floor = 0.063f;

	/// The light floor from the frame's own noise: each frame's noise
	/// deviation is estimated (a median of the Laplacian over a sparse
	/// sample; the rule: front_end/noise_floor.h) and its floor is this
	/// many times that deviation, between light_floor / 2 and light_floor.
	/// The default, 5.3, gives today's 16 grey levels at a noise of 3 and 8
	/// at a quiet sensor's 1.5, finding markers of 7-10 grey levels of
	/// contrast in dark frames; higher keeps the floor nearer light_floor
	/// (fewer edges traced in noisy dark areas), 0 fixes it at light_floor.
	/// Range [0, 100].
	float light_floor_noise = 5.3f;

	/// Corner pixels closer than this (pixels, at the traced resolution)
	/// belong to one corner cluster.
	float corner_cluster_radius = 4.0f;

	/// Candidates whose sides average less than this (full-resolution
	/// pixels), or with a side under 0.6 of it, are dropped before
	/// refinement: below about 1.5 px per cell nothing decodes, but a tilted
	/// marker reads across its foreshortened sides. Lower finds smaller
	/// markers at more cost.
	float min_marker_side = 10.0f;

	/// The largest frame, in pixels, detect() accepts (it throws
	/// std::invalid_argument beyond): a bound on the memory and time a frame
	/// may take, whatever a file or a buffer claims. The default, 2^26
	/// (8192 x 8192), is comfortably above 8K video (7680 x 4320); buffers
	/// grow with the largest frame seen, about 4 bytes a pixel. Range [1,
	/// 2^30].
	long long max_pixels = 1LL << 26;

	/// The most candidate outlines one frame reads (refines, warps,
	/// decodes); the rest are dropped and counted in
	/// Result::candidates_dropped. A bound on the back end's time whatever
	/// the frame shows: a frame full of small squares (a tiled wall, a dot
	/// grid, a perforated sheet) has one candidate per square, tens of
	/// thousands at 4K, where a frame of markers has a few dozen. Kept
	/// first: those the trace's quick read found to be markers, then those
	/// it read within max_hamming of a codeword (a damaged marker), then
	/// those with a readable black frame, then the rest; the smallest first
	/// within each. Lower bounds a frame's time tighter, at the risk of
	/// missing markers among such clutter. Range [1, 2^20].
	int max_candidates = 4096;

	/// Threads; 1 = strictly single-threaded, 0 = one per hardware core. A
	/// Pipeline (Overlap::Frames) runs this many whole frames at once, one per
	/// thread: what pays on a stream (1.8x with two threads, for a frame of
	/// latency per thread and a detector's memory per thread). A
	/// lone Detector, which has one frame at a time, splits its front end
	/// into row bands instead: 0.6-1.0x on 640x480, only worth it on large
	/// frames.
	int threads = 1;
};

} // namespace frappe
