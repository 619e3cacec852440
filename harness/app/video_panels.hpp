// SPDX-License-Identifier: GPL-3.0-or-later
// The panels of a video frame (harness/app/video_maker.hpp), each drawn into a rectangle of a
// Canvas: the depth image, the circle around the listener with the sector being played, the
// top view of the map and the path walked so far, and the frame's numbers as text.
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"
#include "harness/app/video_canvas.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

namespace sonomap::harness {

struct PanelRect {
  int x = 0, y = 0, w = 0, h = 0;
};

// The depth image fitted into `r` (aspect kept), coloured by depth over [0, max_depth];
// pixels with no return are black.
void draw_depth(Canvas& canvas, const PanelRect& r, const Frame& frame, double max_depth);

// Top view around the listener, heading up and left to the left as in the circle picture:
// a ring coloured by each bin's range (grey: unknown), the closest points at their ranges,
// and the sector being played (sector < 0: none) outlined in yellow.
void draw_circle(Canvas& canvas, const PanelRect& r, const Circle& circle,
                 const RasterConfig& config, int sector, int sectors);

// The map seen from above, north up: every surface cell seen so far in the obstacle band (the
// heights the rasters look at: no floor or ceiling), the path and the listener now.
class TopView {
 public:
  explicit TopView(double cell_m = 0.05) : cell_m_(cell_m) {}
  // Points with z in [z_min, z_max] (world) are kept.
  void add_surface(const std::vector<Eigen::Vector3f>& points, double z_min, double z_max);
  void add_pose(const Eigen::Vector2d& position, double heading);
  void draw(Canvas& canvas, const PanelRect& r) const;

 private:
  void extend(const Eigen::Vector2d& p);
  double cell_m_;
  std::unordered_set<std::int64_t> cells_;
  std::vector<Eigen::Vector2d> path_;
  double heading_ = 0.0;
  bool bounded_ = false;
  Eigen::Vector2d min_, max_;  // of cells and path
};

// Lines of text from the top-left of `r`.
void draw_lines(Canvas& canvas, const PanelRect& r, const std::vector<std::string>& lines);

}  // namespace sonomap::harness
