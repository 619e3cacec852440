// SPDX-License-Identifier: GPL-3.0-or-later
// One recorded depth image with its pose, and the Frame the mapper sees made from it: shared by
// every recording format (TUM folders, frame folders, ROS1 bags).
#pragma once

#include "core/types.hpp"
#include "sim/scenario.hpp"

#include <cstdint>
#include <vector>

namespace sonomap::harness {

struct DepthRecord {
  double time = 0.0;  // seconds, in the recording's clock
  int width = 0;
  int height = 0;
  std::vector<double> depth;  // row-major z-depth in metres; 0 (or not finite): no return
  // A point cloud's own points in the camera optical frame (then the frame's points, with or
  // without the image); empty: the points are back-projected from `depth`.
  std::vector<Eigen::Vector3f> points;
  Eigen::Isometry3d world_T_camera = Eigen::Isometry3d::Identity();  // in the recording's world
};

// 16-bit depth units (0 = no return) to metres.
std::vector<double> depth_from_units(const std::vector<std::uint16_t>& units, double units_per_metre);

// The Frame of a record: depth outside [min_range, max_range] dropped, the rest back-projected
// with the camera's intrinsics, or, for a record with points (a cloud), its points with z in that
// range. Poses: the recorded one is both "given" and "true", the body's
// is world_T_camera * body_T_camera^-1. time is relative to `time_zero`.
Frame frame_from_record(int index, const DepthRecord& record, double time_zero,
                        const sim::CameraSpec& camera);

// Median of the valid (non-zero, finite) depths (or the points' z), 0 when there is none.
double median_depth(const DepthRecord& record);

}  // namespace sonomap::harness
