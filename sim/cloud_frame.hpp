// SPDX-License-Identifier: GPL-3.0-or-later
// A depth frame as a point-cloud sensor delivers it: its points only, as an unorganised cloud
// from a recording arrives (no image beside them), or only the points of every n-th image row,
// whose lines across a surface stand in for a spinning lidar's rings.
#pragma once

#include "core/types.hpp"

namespace sonomap::sim {

// Drops the frame's depth image and, with row_step > 1, every point whose pixel (pixel_of:
// the nearest pixel centre) is not on a row that is a multiple of row_step. Throws
// std::invalid_argument for row_step < 1.
void keep_cloud(Frame& frame, int row_step = 1);

}  // namespace sonomap::sim
