// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/cloud_frame.hpp"

#include "core/pixel.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

void keep_cloud(Frame& frame, int row_step) {
  if (row_step < 1) throw std::invalid_argument("keep_cloud: row step " + std::to_string(row_step) + " is below 1");
  frame.depth.clear();  // mappers then read the frame as a cloud without an image
  if (row_step == 1) return;
  auto off_ring = [&](const Eigen::Vector3f& p) {
    const std::optional<Pixel> pixel = pixel_of(frame.intrinsics, frame.width, frame.height, p.cast<double>());
    return !pixel || pixel->v % row_step != 0;
  };
  auto& points = frame.points_camera;
  points.erase(std::remove_if(points.begin(), points.end(), off_ring), points.end());
}

}  // namespace sonomap::sim
