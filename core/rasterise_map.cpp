// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/rasterise_map.hpp"

namespace sonomap {

void rasterise_map(const Mapper& mapper, const RasterOrigin& origin, Rasteriser& rasteriser,
                   std::vector<Eigen::Vector3f>& surface) {
  surface.clear();
  mapper.surface_points(origin.position, rasteriser.config().max_range, surface);
  rasteriser.reset(origin);
  rasteriser.add(surface);
}

}  // namespace sonomap
