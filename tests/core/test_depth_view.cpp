// SPDX-License-Identifier: GPL-3.0-or-later
// The depth image's silhouette tiles as VDB-GPDF reads them (core/vdb_gpdf/depth_view.hpp): a
// whole box's test (may_touch_silhouette, asked once per local leaf) never says "no silhouette
// here" where a point of the box is near one (near_silhouette, asked point by point).
#include "core/vdb_gpdf/depth_view.hpp"

#include <catch2/catch.hpp>

using namespace sonomap;
using gpdf::DepthView;

namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kWallDepth = 3.0, kPanelDepth = 1.5;
constexpr int kPanelLeft = 200, kPanelRight = 300, kPanelTop = 150, kPanelBottom = 350;  // pixels
constexpr double kLeafSize = 0.16;  // a local leaf at 5 cm (8 local voxels of 2 cm)

// A camera at the world's origin looking along +z (the optical frame is the world's): a wall
// 3 m away fills the image, and a panel 1.5 m away covers pixels [200, 300) x [150, 350).
Frame wall_and_panel() {
  Frame frame;
  frame.width = kWidth;
  frame.height = kHeight;
  frame.intrinsics = {525.0, 525.0, 319.5, 239.5};
  frame.depth.assign(static_cast<size_t>(kWidth) * kHeight, static_cast<float>(kWallDepth));
  for (int v = kPanelTop; v < kPanelBottom; ++v)
    for (int u = kPanelLeft; u < kPanelRight; ++u) frame.depth[static_cast<size_t>(v) * kWidth + u] = kPanelDepth;
  return frame;
}

// The world point at pixel (u, v) and depth z.
Eigen::Vector3d at_pixel(const Frame& frame, double u, double v, double z) {
  const PinholeIntrinsics& k = frame.intrinsics;
  return {(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z};
}

Eigen::AlignedBox3d cube_around(const Eigen::Vector3d& centre, double size) {
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(size / 2);
  return {centre - half, centre + half};
}

// Whether any of 9 x 9 x 9 points spread over the box, its corners and faces included, is near a
// silhouette, asked point by point.
bool some_point_near_silhouette(const DepthView& view, const Eigen::AlignedBox3d& box) {
  constexpr int kSteps = 8;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; j <= kSteps; ++j)
      for (int k = 0; k <= kSteps; ++k) {
        const Eigen::Vector3d t(i, j, k);
        if (view.near_silhouette(box.min() + (box.max() - box.min()).cwiseProduct(t / kSteps))) return true;
      }
  return false;
}

}  // namespace

TEST_CASE("a leaf on the flat wall, far from the panel's edges, is clear of silhouettes", "[depth_view]") {
  const Frame frame = wall_and_panel();
  const DepthView view(frame);
  const Eigen::AlignedBox3d box = cube_around(at_pixel(frame, 500, 400, kWallDepth), kLeafSize);
  CHECK_FALSE(view.may_touch_silhouette(box));
  CHECK_FALSE(some_point_near_silhouette(view, box));
}

TEST_CASE("a leaf across the panel's left edge may touch a silhouette, and a point in it does", "[depth_view]") {
  const Frame frame = wall_and_panel();
  const DepthView view(frame);
  const Eigen::AlignedBox3d box = cube_around(at_pixel(frame, kPanelLeft, 250, kPanelDepth), kLeafSize);
  CHECK(view.may_touch_silhouette(box));
  CHECK(some_point_near_silhouette(view, box));
}

TEST_CASE("a leaf outside the image touches no silhouette; one reaching behind the camera is not ruled out",
          "[depth_view]") {
  const Frame frame = wall_and_panel();
  const DepthView view(frame);
  const Eigen::AlignedBox3d right_of_image = cube_around(at_pixel(frame, 700, 240, kWallDepth), kLeafSize);
  CHECK_FALSE(view.may_touch_silhouette(right_of_image));
  CHECK_FALSE(some_point_near_silhouette(view, right_of_image));
  CHECK(view.may_touch_silhouette(cube_around(Eigen::Vector3d(0.0, 0.0, 0.05), kLeafSize)));
}

TEST_CASE("over the whole view, a box ruled out by the leaf test holds no point near a silhouette",
          "[depth_view]") {
  const Frame frame = wall_and_panel();
  const DepthView view(frame);
  int ruled_out = 0, kept = 0;
  // Leaf-sized boxes every 10 pixels across and beyond the image, at the panel's and the wall's
  // depth and between them; a box may straddle the image's edge.
  for (const double depth : {kPanelDepth, 2.2, kWallDepth})
    for (int v = -20; v <= kHeight + 20; v += 10)
      for (int u = -20; u <= kWidth + 20; u += 10) {
        const Eigen::AlignedBox3d box = cube_around(at_pixel(frame, u, v, depth), kLeafSize);
        if (view.may_touch_silhouette(box)) {
          ++kept;
          continue;
        }
        ++ruled_out;
        INFO("box at pixel (" << u << ", " << v << "), depth " << depth << " m");
        REQUIRE_FALSE(some_point_near_silhouette(view, box));
      }
  // Both answers occur: the test rules most of the wall out and keeps the panel's edges.
  CHECK(ruled_out > kept);
  CHECK(kept > 100);
}
