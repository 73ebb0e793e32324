"""The floors the data tests hold the detector to (issue 17), in one table.

Every limit is a pair (enforced, target). `target` is the issue's; `enforced`
is what the tests fail on today. Where the detector does not reach the target
yet, `enforced` is today's measurement rounded a little towards the failing
side, so that main stays green and catches regressions; raise it as the
detector improves, up to the target (then both numbers are equal).

Run the tests with FRAPPE_DATA_FLOORS=target to hold every check to its
target instead: they then fail wherever the issue is not done yet.
"""
import os
from dataclasses import dataclass
from typing import Optional, Tuple

Limit = Optional[Tuple[float, float]]  # (enforced, target)


@dataclass(frozen=True)
class Floor:
    sens: Limit = None    # min sensitivity (matched / truth markers)
    fp: Limit = None      # max false positives (the scorer's: all unmatched detections)
    mae: Limit = None     # max corner mean error of matched markers, px
    large: Limit = None   # min sensitivity of the markers of 60 px or more
    light: Optional[dict] = None  # {effect: Limit}: min sensitivity of the markers
                                  # of the images with that lighting (params.light)


# Frappe at defaults, single thread, on each synthetic subset with its own
# dictionary (frappe-detect, the contract's command).
SETS = {
    'synth/images':             Floor(sens=(0.94, 0.93), fp=(0, 0), mae=(0.20, 0.20)),
    'synth/apriltag36h11':      Floor(sens=(0.95, 0.95), fp=(0, 0), mae=(0.20, 0.20)),
    # Corners under motion blur of 8-12 px stay 1-2 px off (a fifth of the
    # markers give a third of the error): a blurred side's fall overlaps the
    # next edge's (a one-cell quiet zone, a code cell), which no window on
    # the falls undoes. The symmetric window (corner_refine.h) takes back
    # the part a one-sided cut causes: 0.361 -> 0.351 px.
    'synth/blur':               Floor(sens=(0.68, 0.66), fp=(0, 0), mae=(0.36, 0.35), large=(0.97, 0.95)),
    'synth/blur-apriltag36h11': Floor(sens=(0.68, 0.64), fp=(0, 0), large=(0.97, 0.95)),
    # Markers needing a corrected bit: the 4x4 families and 16h5 correct
    # none by default now (as OpenCV's defaults), for no wrong ids.
    'synth/4x4_50':             Floor(sens=(0.99, 0.98), fp=(0, 0)),
    'synth/6x6_250':            Floor(sens=(0.94, 0.93), fp=(0, 0)),
    'synth/apriltag_16h5':      Floor(sens=(0.97, 0.98), fp=(0, 0)),
    'synth/seq01':              Floor(sens=(0.97, 0.97), fp=(2, 2)),
    'synth/seq02':              Floor(sens=(0.97, 0.97), fp=(2, 2)),
    # Hard light (issue 29): the thresholds follow the light, reads on a log
    # scale where grey levels fail.
    # Enforced a little under today's measure (above the targets).
    'synth/lighting':           Floor(sens=(0.87, 0.78), fp=(1, 1), mae=(0.30, 0.30),
                                      light={'lowlight': (0.84, 0.60), 'blinds': (0.79, 0.75),
                                             'cast': (0.85, 0.75), 'glare': (0.86, 0.75),
                                             'overexposed': (0.93, 0.75)}),
    'synth/lighting-apriltag36h11': Floor(sens=(0.82, 0.78), fp=(1, 1), mae=(0.36, 0.36),
                                          light={'lowlight': (0.73, 0.60), 'blinds': (0.77, 0.75),
                                                 'cast': (0.76, 0.75), 'glare': (0.77, 0.75),
                                                 'overexposed': (0.90, 0.75)}),
}

# Any exposure (issue 29): each synthetic subset exposed G times as long
# (frappe-sweep's lightG: v G plus sensor noise of 1.5 grey levels, seeded,
# clipped), in points (0.01) below its own sensitivity as read at most, and
# without a false positive. EXPOSURE_ENFORCED holds, per subset, the points
# enforced where the target is not met yet (a missing entry: the target).
EXPOSURE_POINTS = {0.3: 3, 0.15: 10, 2.0: 3}
# Not met yet: at 200% light small blurred markers lose their black cells
# to the ceiling (their blur lifts them to within a few grey levels of it,
# or their border so near it that no edge or dark region closes around
# them); the lighting subsets, already dim or clipped, darkened or
# brightened again (glare brightened twice clips the black ink itself).
# Darkened, the lighting subsets lose what falls below 10 grey levels of
# contrast (at 15%: 259 of lighting's 499 markers; their markers of 10 or
# more are found as often as at 1x): the 14/32 and 14/28 points are that
# ceiling (docs/quality.md, "Low exposure by contrast"; the light floor from
# the frame's noise took back 2 and 1 points at 15%).
# apriltag_16h5 meets the 3 points at 200% since clipped candidates are no
# longer skipped as clutter (docs/quality.md, issue 29); synth/images and
# lighting missed them by 0.05 and 0.2 points once the noise floor raised
# their 1x (0.9415 -> 0.9428, 0.8898 -> 0.8938; 200% unchanged).
# The centre reads' paper test and binariseInLight() (issue 29 item 2) raised
# lighting's 1x by 10 markers (0.8938 -> 0.9138) and its 15%, 30% and 200% by
# 5, 6 and 4 (0.5832 -> 0.5932, 0.7615 -> 0.7735, 0.8417 -> 0.8497): a point
# more enforced at each.
EXPOSURE_ENFORCED = {
    ('synth/blur', 2.0): 6, ('synth/blur-apriltag36h11', 2.0): 7, ('synth/4x4_50', 2.0): 5,
    ('synth/6x6_250', 2.0): 5, ('synth/images', 2.0): 4,
    ('synth/lighting', 0.15): 33, ('synth/lighting', 0.3): 15, ('synth/lighting', 2.0): 7,
    ('synth/lighting-apriltag36h11', 0.15): 28, ('synth/lighting-apriltag36h11', 0.3): 14,
    ('synth/lighting-apriltag36h11', 2.0): 8,
}
# False positives allowed where the target of none is not met yet. (The 15 px
# marker of synth/images read as another id at 30% is no longer read since the
# light floor follows the frame's noise.)
EXPOSURE_FP_ENFORCED = {('synth/lighting', 2.0): 1}

# Photographs: every marker of the folders with source ground truth found
# (detector-labelled folders are incomplete: not counted), and in every folder
# no detection misplaced on a labelled marker (wrong id, orientation, right id
# with corners off, duplicate). Detections away from every label are not
# counted: photographs hold markers nobody labelled.
REAL_MISSED = (0, 0)
REAL_MISPLACED = (0, 0)

# Wrong ids per 300 frames of each dictionary over every synthetic subset of
# the other families (and its false positives on a subset of its own family
# in another size), at defaults. Detections of a printed marker whose code
# is also a code of the asked dictionary (within what it corrects) are right
# by that dictionary and not charged; the tests print them apart.
# 4x4_1000: 12 of its 19 are random-bit distractors that are valid 4x4_1000
# codewords, printed markers by that dictionary's reading.
WRONG_IDS_PER_300 = {
    '4x4_50': (1, 1), '4x4_100': (1, 1), '4x4_250': (1, 1), '4x4_1000': (4, 1),
    '5x5_50': (1, 1), '5x5_100': (1, 1), '5x5_250': (1, 1), '5x5_1000': (1, 1),
    '6x6_50': (1, 1), '6x6_100': (1, 1), '6x6_250': (1, 1), '6x6_1000': (1, 1),
    '7x7_50': (1, 1), '7x7_100': (1, 1), '7x7_250': (1, 1), '7x7_1000': (1, 1),
    'apriltag_16h5': (1, 1), 'apriltag_25h9': (1, 1), 'apriltag_36h10': (1, 1),
    'apriltag_36h11': (1, 1), 'aruco_mip_36h12': (1, 1), 'aruco_original': (1, 1),
    # AprilTag 3's layout families (issue 32): none over any subset, measured.
    'apriltag_standard41h12': (0, 0), 'apriltag_standard52h13': (0, 0), 'apriltag_circle21h7': (0, 0),
    'apriltag_circle49h12': (0, 0), 'apriltag_custom48h12': (0, 0),
}

# Any resolution: each subset upsampled 2x and 3x, bilinear and nearest,
# must keep its sensitivity within RESOLUTION_POINTS points (0.01 = 1 point)
# of the same subset as read: that is the target. The floors are the
# upsampled sensitivities themselves, so that a better 1x never fails them;
# None holds a copy to the target itself.
RESOLUTION_POINTS = 2
RESOLUTION = {
    #                            2x linear  2x nearest  3x linear  3x nearest
    'synth/images':             (0.93,      0.92,       0.92,      0.92),
    'synth/apriltag36h11':      (0.95,      0.95,       0.95,      0.95),
    'synth/blur':               (0.67,      0.66,       0.66,      0.66),
    'synth/blur-apriltag36h11': (0.66,      0.66,       0.65,      0.66),
    'synth/4x4_50':             (0.98,      0.97,       0.97,      0.96),
    'synth/6x6_250':            (0.93,      0.93,       0.93,      0.92),
    'synth/apriltag_16h5':      (0.96,      0.96,       0.96,      0.95),
    'synth/seq01':              (None,      None,       None,      None),
    'synth/seq02':              (None,      None,       None,      None),
    # Hard light upsampled loses 3-7 points: not met yet.
    'synth/lighting':           (0.85,      0.84,       0.83,      0.84),
    'synth/lighting-apriltag36h11': (0.77,  0.78,       0.75,      0.75),
}


def at_target():
    return os.environ.get('FRAPPE_DATA_FLOORS', '') == 'target'


# Mode::Track against Mode::Normal on the same sequence, same run (issue 35):
# how far below NORMAL's sensitivity tracking may fall, how many more false
# positives and dropouts (the scorer's) it may have, and how many frames after
# NORMAL first finds a marker tracking may find it (k - 1, k =
# track_cover_frames' default of 4). Speed is measured, not asserted
# (docs/tracking.md).
TRACK = {
    'sens_below_normal': (0.005, 0.005),
    'fp_above_normal': (0, 0),
    'dropouts_above_normal': (0, 0),
    'frames_late': (3, 3),
}


def enforced(limit):
    """The number a check fails on: the floor, or the target when asked."""
    return limit[1] if at_target() else limit[0]
