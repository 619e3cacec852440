// SPDX-License-Identifier: GPL-3.0-or-later
// Moved-object ghosts (eval/moved_ghosts.hpp): a 0.4 x 0.4 x 1.5 m box stands 1.3 m ahead (its
// front face) of a camera 1 m above the floor, with a wall 3 m ahead; then it leaves. The depth
// images are closed-form ray casts of the wall and the box, and the circles are written by hand:
// the "map" keeps reading the box's front face for as many frames as each case says.
#include "eval/moved_ghosts.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace sonomap;

namespace {

constexpr double kWallX = 3.0, kFaceX = 1.3, kEyeZ = 1.0;
const Eigen::AlignedBox3d kBoxLocal(Eigen::Vector3d(-0.2, -0.2, 0.0), Eigen::Vector3d(0.2, 0.2, 1.5));
const Eigen::Vector3d kBoxAt(1.5, 0.0, 0.0);  // the box's place: x in [1.3, 1.7], y in [-0.2, 0.2]

Eigen::Isometry3d translation(const Eigen::Vector3d& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = p;
  return t;
}

// The camera at (0, 0, 1): looking along +x (yaw 0) or, turned round, along -x (yaw 180).
Eigen::Isometry3d camera(double yaw_deg = 0.0) {
  Eigen::Matrix3d optical;  // optical z = body x, optical x = -body y, optical y = -body z
  optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() * optical;
  t.translation() = Eigen::Vector3d(0, 0, kEyeZ);
  return t;
}

// Nearest hit along the ray e + t d of the axis-aligned box, or infinity (slab method).
double hit_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& e, const Eigen::Vector3d& d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (e[a] < box.min()[a] || e[a] > box.max()[a]) return t1;
      continue;
    }
    double lo = (box.min()[a] - e[a]) / d[a], hi = (box.max()[a] - e[a]) / d[a];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

// A 64 x 48 z-depth image (fx = fy = 40) of the wall x = 3 and the box at `box_at` if any.
Frame depth_image(const std::optional<Eigen::Vector3d>& box_at, const Eigen::Isometry3d& world_T_camera) {
  Frame f;
  f.width = 64;
  f.height = 48;
  f.intrinsics = {40.0, 40.0, 31.5, 23.5};
  f.depth.assign(static_cast<std::size_t>(f.width * f.height), 0.0f);
  for (int v = 0; v < f.height; ++v)
    for (int u = 0; u < f.width; ++u) {
      // Optical ray with z = 1: the ray parameter is the z-depth.
      const Eigen::Vector3d ray((u - 31.5) / 40.0, (v - 23.5) / 40.0, 1.0);
      const Eigen::Vector3d d = world_T_camera.linear() * ray, e = world_T_camera.translation();
      double t = d.x() > 0 ? (kWallX - e.x()) / d.x() : std::numeric_limits<double>::infinity();
      if (box_at) {
        const Eigen::AlignedBox3d box(kBoxLocal.min() + *box_at, kBoxLocal.max() + *box_at);
        t = std::min(t, hit_box(box, e, d));
      }
      if (std::isfinite(t)) f.depth[static_cast<std::size_t>(v * f.width + u)] = static_cast<float>(t);
    }
  return f;
}

// Bin k's azimuth (its centre, degrees, counter-clockwise from ahead = +x).
double azimuth_deg(int k) { return k + 0.5 > 180.0 ? k + 0.5 - 360.0 : k + 0.5; }

// A circle reading the vertical plane x = `plane_x` in the bins within `half_width_deg` of
// ahead, at the camera's height.
void read_plane(Circle& c, double plane_x, double half_width_deg) {
  for (int k = 0; k < c.size(); ++k) {
    const double a = azimuth_deg(k) * M_PI / 180.0;
    if (std::abs(azimuth_deg(k)) >= half_width_deg) continue;
    c.bins[k].range = static_cast<float>(plane_x / std::cos(a));
    c.bins[k].point = Eigen::Vector3f(static_cast<float>(plane_x), static_cast<float>(plane_x * std::tan(a)), kEyeZ);
  }
}

constexpr double kBoxHalfDeg = 7.0;  // bins 0..6 and 353..359: on the box's face (|y| < 0.16)
constexpr int kBoxBins = 14;

// The truth: the wall, and the box's face when it is there.
Circle truth_circle(bool box_there) {
  Circle c(360);
  read_plane(c, kWallX, 60.0);
  if (box_there) read_plane(c, kFaceX, kBoxHalfDeg);
  return c;
}

// The map: the wall, and the box's face while it still holds it.
Circle map_circle(bool holds_box) { return truth_circle(holds_box); }

struct Script {
  int frames = 30;
  int leaves = 10;          // the box is gone from this frame on
  int map_forgets = 10;     // the map reads the box until the frame before this one
  int every = 1;            // evaluated frames: multiples of this (and the last)
  double turn_away = -1.0;  // from `leaves` on the camera looks this way (yaw, degrees); <0: never
  bool moved_not_removed = false;  // the box moves 3 m to the side instead of leaving the scene
};

std::vector<eval::MovedObjectClearing> play(const Script& s, std::vector<eval::MovedGhostFrame>* frames = nullptr) {
  eval::MovedGhostsConfig config;  // tolerance 0.1 m, band 0.1 to 2 m above z = 0
  eval::MovedGhosts tracker({{"box", kBoxLocal}}, config);
  for (int i = 0; i < s.frames; ++i) {
    if (i % s.every != 0 && i != s.frames - 1) continue;
    const bool there = i < s.leaves;
    const Eigen::Isometry3d cam = camera(!there && s.turn_away >= 0.0 ? s.turn_away : 0.0);
    std::optional<Eigen::Vector3d> at;
    if (there) at = kBoxAt;
    else if (s.moved_not_removed) at = kBoxAt + Eigen::Vector3d(0, -3.0, 0);
    std::vector<std::optional<Eigen::Isometry3d>> poses{std::nullopt};
    if (at) poses[0] = translation(*at);
    const auto out = tracker.add_frame(i, poses, map_circle(i < s.map_forgets), truth_circle(there),
                                       depth_image(at, cam), cam);
    if (frames) frames->push_back(out);
  }
  return tracker.results();
}

}  // namespace

TEST_CASE("Moved ghosts: a box whose ghost stays 5 frames after its place is seen empty clears in 5",
          "[moved_ghosts]") {
  Script s;
  s.map_forgets = 15;
  std::vector<eval::MovedGhostFrame> frames;
  const auto r = play(s, &frames);
  REQUIRE(r.size() == 1);
  CHECK(r[0].name == "box");
  CHECK(r[0].seen_empty_frame == 10);  // the wall is seen through the old place at once
  CHECK(r[0].clearing_frames == 5);    // read at 10..14, none from 15
  CHECK(r[0].cleared());
  CHECK(r[0].ghost_bins_at_end == 0);
  CHECK(r[0].max_ghost_bins == kBoxBins);
  CHECK(r[0].ghost_frames == 5);
  // Per frame: no reading while the box stands (it is the truth then), 14 bins while the ghost lasts.
  CHECK(frames[9].bins == 0);
  CHECK(frames[10].bins == kBoxBins);
  CHECK(frames[10].seen_bins == kBoxBins);
  CHECK(frames[10].objects[0].seen == kBoxBins);
  CHECK(frames[14].seen_bins == kBoxBins);
  CHECK(frames[15].bins == 0);
}

TEST_CASE("Moved ghosts: a map that forgets at once clears in 0 frames, one that forgets a frame late in 1",
          "[moved_ghosts]") {
  Script s;
  s.map_forgets = s.leaves;
  CHECK(play(s)[0].clearing_frames == 0);
  s.map_forgets = s.leaves + 1;
  CHECK(play(s)[0].clearing_frames == 1);
  // The same when the box is pushed 3 m aside (still in the scene, out of view) instead of removed.
  s.moved_not_removed = true;
  const auto r = play(s);
  CHECK(r[0].seen_empty_frame == 10);
  CHECK(r[0].clearing_frames == 1);
}

TEST_CASE("Moved ghosts: a map that never forgets is reported as never cleared, with its ghost bins",
          "[moved_ghosts]") {
  Script s;
  s.map_forgets = s.frames;
  const auto r = play(s);
  CHECK(r[0].seen_empty_frame == 10);
  CHECK_FALSE(r[0].clearing_frames.has_value());
  CHECK_FALSE(r[0].cleared());
  CHECK(r[0].ghost_bins_at_end == kBoxBins);
  CHECK(r[0].unseen_ghost_bins_at_end == 0);
  CHECK(r[0].ghost_frames == 20);
}

TEST_CASE("Moved ghosts: an old place the camera never sees empty has no clearing figure",
          "[moved_ghosts]") {
  Script s;
  s.map_forgets = s.frames;
  s.turn_away = 180.0;  // the camera turns its back on the box as it leaves
  const auto r = play(s);
  CHECK_FALSE(r[0].seen_empty_frame.has_value());
  CHECK_FALSE(r[0].clearing_frames.has_value());
  CHECK(r[0].ghost_bins_at_end == 0);  // the ghost's place was never seen empty ...
  CHECK(r[0].unseen_ghost_bins_at_end == kBoxBins);  // ... but the bins still read it
  CHECK(r[0].ghost_frames == 0);
  std::vector<eval::MovedGhostFrame> frames;
  play(s, &frames);
  CHECK(frames.back().bins == kBoxBins);  // frames.csv counts them ...
  CHECK(frames.back().seen_bins == 0);    // ... but not as a map's failure to clear
}

TEST_CASE("Moved ghosts: figures count evaluated frames (--every)", "[moved_ghosts]") {
  Script s;
  s.every = 3;
  s.map_forgets = 15;  // evaluated: ... 9 (box), 12 (ghost, seen empty), 15 (clear)
  const auto r = play(s);
  CHECK(r[0].seen_empty_frame == 12);
  CHECK(r[0].clearing_frames == 3);
}

TEST_CASE("Moved ghosts: a ghost bin away from the object's old place is not the object's",
          "[moved_ghosts]") {
  eval::MovedGhosts tracker({{"box", kBoxLocal}}, {});
  const Eigen::Isometry3d cam = camera();
  tracker.add_frame(0, {translation(kBoxAt)}, truth_circle(true), truth_circle(true), depth_image(kBoxAt, cam), cam);
  // The box has gone; the map reads nothing of it, but bins 20..24 read a phantom 1 m nearer
  // than the wall, 1 m to the left of the box's old place.
  Circle map = truth_circle(false);
  for (int k = 20; k < 25; ++k) {
    const double a = azimuth_deg(k) * M_PI / 180.0, r = 2.0 / std::cos(a);
    map.bins[k].range = static_cast<float>(r);
    map.bins[k].point = Eigen::Vector3f(2.0f, static_cast<float>(2.0 * std::tan(a)), kEyeZ);
  }
  const auto out = tracker.add_frame(1, {std::nullopt}, map, truth_circle(false), depth_image(std::nullopt, cam), cam);
  CHECK(out.bins == 0);
  CHECK(out.seen_bins == 0);
  CHECK(out.objects[0].seen == 0);
  CHECK(out.objects[0].unseen == 0);
  CHECK(tracker.results()[0].clearing_frames == 0);
}

TEST_CASE("Moved ghosts: bad input is refused", "[moved_ghosts]") {
  eval::MovedGhostsConfig bad;
  bad.tolerance = -0.1;
  CHECK_THROWS_AS(eval::MovedGhosts({{"box", kBoxLocal}}, bad), std::invalid_argument);
  CHECK_THROWS_AS(eval::MovedGhosts({{"empty", Eigen::AlignedBox3d()}}, {}), std::invalid_argument);
  eval::MovedGhosts tracker({{"box", kBoxLocal}}, {});
  const Eigen::Isometry3d cam = camera();
  const Frame depth = depth_image(std::nullopt, cam);
  CHECK_THROWS_AS(tracker.add_frame(0, {}, Circle(360), Circle(360), depth, cam), std::invalid_argument);
  CHECK_THROWS_AS(tracker.add_frame(0, {std::nullopt}, Circle(360), Circle(36), depth, cam), std::invalid_argument);
  tracker.add_frame(5, {std::nullopt}, Circle(360), Circle(360), depth, cam);
  CHECK_THROWS_AS(tracker.add_frame(5, {std::nullopt}, Circle(360), Circle(360), depth, cam), std::invalid_argument);
}

TEST_CASE("Moved ghosts: a ghost at the image's edge is seen empty when the camera looks through "
          "the ghost itself, though its cell's centre is out of view",
          "[moved_ghosts]") {
  eval::MovedGhosts tracker({{"box", kBoxLocal}}, {});
  tracker.add_frame(0, {translation(kBoxAt)}, truth_circle(true), truth_circle(true),
                    depth_image(kBoxAt, camera()), camera());
  // The box has gone and the camera has turned 33.6 degrees left: the image's right edge
  // (38.7 degrees off its axis) now passes between two ghost points the map still holds on the
  // box's old front face. Inside: (1.31, -0.11, 1) at 38.4 degrees (pixel column 63.2 of 64),
  // while the centre of its 5 cm cell, (1.325, -0.125, 1.025), is at 39.0 degrees (column
  // 63.9: out). Outside: (1.31, -0.16, 1) at 40.6 degrees.
  const Eigen::Isometry3d turned = camera(33.6);
  Circle map = truth_circle(false), truth = truth_circle(false);
  const Eigen::Vector3f inside(1.31f, -0.11f, 1.0f), outside(1.31f, -0.16f, 1.0f);
  for (const auto& [bin, point] : {std::pair{355, inside}, std::pair{353, outside}}) {
    map.bins[bin].point = point;
    map.bins[bin].range = point.head<2>().norm();
  }
  const auto out = tracker.add_frame(1, {std::nullopt}, map, truth, depth_image(std::nullopt, turned), turned);
  CHECK(out.bins == 2);
  CHECK(out.objects[0].seen == 1);
  CHECK(out.objects[0].unseen == 1);
  CHECK(out.seen_bins == 1);
}
