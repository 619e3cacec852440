// SPDX-License-Identifier: GPL-3.0-or-later
// A map's circle and cylinder around the listener: the mapper's surface samples in the obstacle
// band within the raster's max_range, added to the rasteriser reset on the origin. `run` and
// `bench map` both build rasters with this one call.
#pragma once

#include "core/mapper.hpp"
#include "core/rasteriser.hpp"

#include <Eigen/Core>
#include <vector>

namespace sonomap {

// `surface` is reused scratch and holds the band's samples afterwards (the video's top view
// draws them).
void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   std::vector<Eigen::Vector3f>& surface);

}  // namespace sonomap
