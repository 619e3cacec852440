// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/sequence_frame.hpp"

#include <algorithm>
#include <cmath>

namespace sonomap::harness {

std::vector<double> depth_from_units(const std::vector<std::uint16_t>& units, double units_per_metre) {
  std::vector<double> depth(units.size());
  for (std::size_t i = 0; i < units.size(); ++i) depth[i] = units[i] / units_per_metre;
  return depth;
}

Frame frame_from_record(int index, const DepthRecord& record, double time_zero,
                        const sim::CameraSpec& camera) {
  Frame frame;
  frame.index = index;
  frame.time = record.time - time_zero;
  frame.width = record.width;
  frame.height = record.height;
  frame.intrinsics = PinholeIntrinsics{camera.fx, camera.fy, camera.cx, camera.cy};
  frame.depth.assign(record.depth.size(), 0.0f);
  for (const Eigen::Vector3f& p : record.points)
    if (p.z() >= camera.min_range && p.z() <= camera.max_range) frame.points_camera.push_back(p);
  for (int v = 0; v < record.height; ++v) {
    for (int u = 0; u < record.width; ++u) {
      const std::size_t k = static_cast<std::size_t>(v) * record.width + u;
      const double z = record.depth[k];
      if (!std::isfinite(z) || z <= 0.0 || z < camera.min_range || z > camera.max_range) continue;
      frame.depth[k] = static_cast<float>(z);
      if (!record.points.empty()) continue;  // a cloud brings its own points
      frame.points_camera.emplace_back(static_cast<float>((u - camera.cx) * z / camera.fx),
                                       static_cast<float>((v - camera.cy) * z / camera.fy),
                                       static_cast<float>(z));
    }
  }
  frame.world_T_camera = record.world_T_camera;
  frame.world_T_body = record.world_T_camera * camera.body_T_camera.inverse();
  return frame;
}

double median_depth(const DepthRecord& record) {
  std::vector<double> valid;
  for (double z : record.depth)
    if (std::isfinite(z) && z > 0.0) valid.push_back(z);
  if (record.depth.empty())
    for (const Eigen::Vector3f& p : record.points) valid.push_back(p.z());
  if (valid.empty()) return 0.0;
  const auto middle = valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2);
  std::nth_element(valid.begin(), middle, valid.end());
  return *middle;
}

}  // namespace sonomap::harness
