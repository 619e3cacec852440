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

// What rasterise_map() reuses from call to call: the spans the map hands over and, for a map
// that copies its samples, their copy.
struct RasterScratch {
  std::vector<SampleSpan> spans;
  std::vector<Eigen::Vector3f> points;
};

// Reads the map's samples in place (Mapper::surface_spans_in_band).
void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   RasterScratch& scratch);

// The samples the rasters take, as a copy (Mapper::surface_points_in_band over the same band
// and disc): what the video's top view draws.
void band_samples(const Mapper& mapper, const RasterOrigin& origin, const RasterConfig& config,
                  std::vector<Eigen::Vector3f>& out);

}  // namespace sonomap
