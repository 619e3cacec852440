// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasterise_map.hpp"

namespace sonomap {

namespace {

// The world heights asked of the map. The rasteriser keeps heights z - ground_z in the band;
// the map is asked for a band 1 mm wider, so that no sample it keeps is lost to rounding in
// z_min or z_max.
struct BandHeights {
  double z_min, z_max;
};
BandHeights band_heights(const RasterOrigin& origin, const RasterConfig& config) {
  constexpr double kMargin = 1e-3;
  return {origin.ground_z + config.band_min - kMargin, origin.ground_z + config.band_max + kMargin};
}

}  // namespace

void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   RasterScratch& scratch) {
  const RasterConfig& c = rasteriser.config();
  const BandHeights band = band_heights(origin, c);
  scratch.spans.clear();
  mapper.surface_spans_in_band(origin.position, c.max_range, band.z_min, band.z_max, scratch.spans,
                               scratch.points);
  rasteriser.reset(origin);
  rasteriser.add(scratch.spans);
}

void band_samples(const Mapper& mapper, const RasterOrigin& origin, const RasterConfig& config,
                  std::vector<Eigen::Vector3f>& out) {
  const BandHeights band = band_heights(origin, config);
  out.clear();
  mapper.surface_points_in_band(origin.position, config.max_range, band.z_min, band.z_max, out);
}

}  // namespace sonomap
