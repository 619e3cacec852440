# SPDX-License-Identifier: GPL-3.0-or-later
"""The closed-form circle of square_room.yaml: an independent truth for the tests."""
import math

import numpy as np

POSITION, HEADING_DEG, HALF_SIDE = (0.3, -0.2), 30.0, 2.0


def square_room_circle(bins):
    """Per bin, the least horizontal distance to the walls x, y = +-2 over the bin's wedge.
    The room is convex: along direction t a wall with normal angle p at distance d is met at
    d / cos(t - p), the nearest wall first; over a wedge that is least where the wedge comes
    closest to the wall's normal."""
    x, y = POSITION
    walls = [(HALF_SIDE - x, 0.0), (HALF_SIDE + x, 180.0), (HALF_SIDE - y, 90.0), (HALF_SIDE + y, 270.0)]
    width = 360.0 / bins
    out = np.empty(bins)
    for k in range(bins):
        lo, hi = HEADING_DEG + k * width, HEADING_DEG + (k + 1) * width
        best = math.inf
        for distance, normal in walls:
            # The wedge's angle nearest to the normal (wrapped to within 180 degrees of it).
            off = [((a - normal + 180.0) % 360.0) - 180.0 for a in (lo, hi)]
            nearest = 0.0 if off[0] <= 0.0 <= off[1] else min(off, key=abs)
            if abs(nearest) < 90.0:
                best = min(best, distance / math.cos(math.radians(nearest)))
        out[k] = best
    return out
