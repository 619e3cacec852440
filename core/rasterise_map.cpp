// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasterise_map.hpp"

namespace sonomap {

void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   std::vector<Eigen::Vector3f>& surface) {
  // The rasteriser keeps heights z - ground_z in the band; the map is asked for a band 1 mm
  // wider, so that no sample it keeps is lost to rounding in z_min or z_max.
  constexpr double kMargin = 1e-3;
  const RasterConfig& c = rasteriser.config();
  surface.clear();
  mapper.surface_points_in_band(origin.position, c.max_range, origin.ground_z + c.band_min - kMargin,
                                origin.ground_z + c.band_max + kMargin, surface);
  rasteriser.reset(origin);
  rasteriser.add(surface);
}

}  // namespace sonomap
