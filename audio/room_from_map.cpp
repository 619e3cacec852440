// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/room_from_map.hpp"

#include <algorithm>

namespace sonomap::audio {

ShoeboxRoom room_from_map(const std::vector<Eigen::Vector3f>& map_points,
                          const Eigen::Vector3d& listener, double ground_z) {
  Eigen::Vector3d lo = listener, hi = listener;
  for (const auto& p : map_points) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  lo.z() = std::min(lo.z(), ground_z);
  const Eigen::Vector3d min_size(2.0, 2.0, 2.4), centre = 0.5 * (lo + hi);
  lo = lo.cwiseMin(centre - 0.5 * min_size);
  hi = hi.cwiseMax(centre + 0.5 * min_size);
  lo = lo.cwiseMin(listener - Eigen::Vector3d::Constant(0.3));
  hi = hi.cwiseMax(listener + Eigen::Vector3d::Constant(0.3));
  ShoeboxRoom room;
  room.min_corner = lo;
  room.max_corner = hi;
  return room;
}

}  // namespace sonomap::audio
