// SPDX-License-Identifier: GPL-3.0-or-later
// VDB-GPDF's view of one frame's depth image (or of a point cloud's cube of ranges): whether a
// point lies in front of or behind what the sensor measured. Internal to core/vdb_gpdf*.
#pragma once

#include "core/mapper.hpp"
#include "core/parallel.hpp"
#include "core/pixel.hpp"
#include "core/types.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace sonomap::gpdf {

// The widest spacing of a lidar's rings that a ring's neighbourhood (surface_normal), the search
// for the next rings (CubeRangeImage::next_rings) and a lateral vote (CubeRangeImage::measured_around)
// bridge.
constexpr double kRingSpacingDeg = 3.0;
// A lateral vote beyond what a cloud measured (the sensor's field of view ends there) stands
// only where a measured surface within kRingSpacingDeg lies within this many voxels of its
// range: the surface ran on up to the view's edge. At 2 voxels (in a first form of the rule,
// any measured cell in eight directions), rings missed more at the view's edge (random box
// rooms, low boxes: 2 against the TSDF peer's 1).
constexpr double kRunsOnVoxels = 4.0;

// A frame without a depth image (a point cloud) seen as one, so that DepthView's checks hold
// for clouds too: the nearest point in each direction, on the six faces of a cube around the
// camera, each face a 90-degree pinhole image of kCubeCells x kCubeCells cells (0.25 degree at
// a face's centre, as fine as a depth camera's pixels, finer than a lidar's rings: a cell the
// cloud leaves empty says nothing, where an image's empty pixel is a ray that met nothing).
// Depths are along the face's axis, as a pinhole image's are along z. Before it, clouds skipped
// every check: rays carved the random box rooms' edges off (docs/fidelity.md: 28 corner bins
// read too far, the TSDF peer 6) and an object stepping into space the map held free took 36
// frames to reach the map.
class CubeRangeImage {
 public:
  static constexpr int kCubeCells = 360;

  explicit CubeRangeImage(const std::vector<Eigen::Vector3f>& points)
      : points_(points), depth_(6 * kCubeCells * kCubeCells, 0.0f), nearest_(depth_.size(), -1) {
    std::vector<int> cells;
    cells.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const std::optional<Cell> c = cell_of(points[i].cast<double>());
      if (!c) continue;
      float& d = depth_[c->index];
      if (d == 0.0f || c->depth < d) {
        d = static_cast<float>(c->depth);
        nearest_[c->index] = static_cast<int>(i);
      }
      cells.push_back(c->index);
    }
    // Dense: most measured cells have another within two cells along both axes of their face
    // (a lidar's rings are several cells apart across them).
    size_t surrounded = 0;
    for (const int index : cells) surrounded += measured_nearby(index, 1, 0) && measured_nearby(index, 0, 1);
    dense_ = 2 * surrounded > cells.size();
  }

  // A camera-frame point's cell and its depth along the cell's face axis (none at the camera or
  // for a non-finite point).
  struct Cell {
    int index;
    double depth;
  };
  static std::optional<Cell> cell_of(const Eigen::Vector3d& c) {
    if (!c.allFinite()) return std::nullopt;
    int axis = 0;
    c.cwiseAbs().maxCoeff(&axis);
    const double depth = std::abs(c[axis]);
    if (!(depth > 0.0)) return std::nullopt;
    const int face = 2 * axis + (c[axis] < 0.0 ? 1 : 0);
    const int u = cell_coordinate(c[(axis + 1) % 3] / depth), v = cell_coordinate(c[(axis + 2) % 3] / depth);
    return Cell{(face * kCubeCells + v) * kCubeCells + u, depth};
  }

  // Whether the cell and the 8 around it on its face measured something, all of it farther
  // than `depth`. (A cell a cloud left empty says nothing: no ray may have passed there.)
  bool farther_around(int index, double depth) const {
    bool measured = false;
    const int u = index % kCubeCells, v = (index / kCubeCells) % kCubeCells;
    const int face_start = index - v * kCubeCells - u;
    for (int y = std::max(v - 1, 0); y <= std::min(v + 1, kCubeCells - 1); ++y)
      for (int x = std::max(u - 1, 0); x <= std::min(u + 1, kCubeCells - 1); ++x) {
        const float d = depth_[static_cast<size_t>(face_start + y * kCubeCells + x)];
        if (d > 0.0f && d <= depth) return false;
        measured = measured || d > 0.0f;
      }
    return measured;
  }

  // The nearest depth measured in the cell (0: none).
  float depth(int index) const { return depth_[static_cast<size_t>(index)]; }

  // Whether the cloud measured around camera-frame point c (in cell `index`), so that a
  // lateral vote there fills a gap instead of running past what the sensor saw: its own cell
  // measured; or cells on both sides of it within kRingSpacingDeg (between two rings); or,
  // beyond the field of view's edge, the nearest measured cell in eight directions within
  // kRunsOnVoxels of c's range (the surface ran on up to the edge), and for a dense cloud no
  // more than a voxel from c. Votes beyond the view were never checked by a later frame:
  // a table's corner that stayed just below the view grew 7.6 cm past it (docs/fidelity.md).
  bool measured_around(const Eigen::Vector3d& c, int index, double voxel) const {
    if (depth_[static_cast<size_t>(index)] > 0.0f) return true;
    const Eigen::Vector3d d = c.normalized();
    Eigen::Vector3d a = d.cross(Eigen::Vector3d::UnitX());
    if (a.norm() < 0.1) a = d.cross(Eigen::Vector3d::UnitY());
    a.normalize();
    const Eigen::Vector3d b = d.cross(a);
    const double range = c.norm();
    int nearest_step = std::numeric_limits<int>::max();
    bool runs_on = false;  // at the nearest measured cell (the view's edge lies across it)
    auto measured_along = [&](const Eigen::Vector3d& axis) {
      const std::optional<Measured> m = first_measured(d, axis);
      if (!m) return false;
      const bool close = std::abs(m->range - range) < kRunsOnVoxels * voxel;
      if (m->step < nearest_step) runs_on = close;
      else if (m->step == nearest_step) runs_on = runs_on || close;
      nearest_step = std::min(nearest_step, m->step);
      return true;
    };
    const bool a_up = measured_along(a), a_down = measured_along(-a);
    if (a_up && a_down) return true;
    const bool b_up = measured_along(b), b_down = measured_along(-b);
    if (b_up && b_down) return true;
    for (const Eigen::Vector3d& diagonal : {Eigen::Vector3d((a + b).normalized()), Eigen::Vector3d((a - b).normalized())}) {
      measured_along(diagonal);
      measured_along(-diagonal);
    }
    // A dense cloud's surfaces end where its points end: a vote runs on past the edge by a
    // voxel at most (a lidar's rings leave gaps at the view's edge as wide as their spacing).
    return runs_on && (!dense_ || nearest_step * kStepTangent * range <= voxel);
  }

  // The nearest points the cloud measured on the next ring, and on request the one after, on
  // one side (`side`: +1 or -1) of a ring's line through camera-frame point c, across the
  // line's image: past c's own ring (the cells measured around c), the first measured cell
  // within kRingSpacingDeg (next_rings), and past that ring the first within twice that
  // (add_second_ring, which walks on from the first; none where nothing was measured).
  struct NextRings {
    std::optional<Eigen::Vector3d> first, second;
    // Where add_second_ring walks on from: the cube's own camera-frame walk, which the world
    // frame's callers pass back untouched.
    struct Walk {
      Eigen::Vector3d from = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::Zero();
      int first_step = 0;
    } walk;
  };
  NextRings next_rings(const Eigen::Vector3d& c, const Eigen::Vector3d& line, double side) const {
    NextRings rings;
    NextRings::Walk& walk = rings.walk;
    walk.from = c.normalized();
    const Eigen::Vector3d across = walk.from.cross(line);  // in the image, across the line's image
    if (!(across.norm() > 1e-6)) return rings;  // the line runs along the line of sight
    walk.axis = side * across.normalized();
    const std::optional<Measured> first = first_measured(walk.from, walk.axis, true);
    if (!first) return rings;
    rings.first = point_of(*first);
    walk.first_step = first->step;
    return rings;
  }
  void add_second_ring(NextRings& rings) const {
    if (!rings.first) return;
    const std::optional<Measured> second =
        first_measured(rings.walk.from, rings.walk.axis, true, rings.walk.first_step + 1, 2 * kRingSteps);
    if (second) rings.second = point_of(*second);
  }

  // The camera-frame point at `depth` along the centre of cell `index`.
  static Eigen::Vector3d point(int index, double depth) {
    const int u = index % kCubeCells, v = (index / kCubeCells) % kCubeCells, face = index / (kCubeCells * kCubeCells);
    const int axis = face / 2;
    Eigen::Vector3d c;
    c[axis] = face % 2 ? -depth : depth;
    c[(axis + 1) % 3] = ((u + 0.5) * 2.0 / kCubeCells - 1.0) * depth;
    c[(axis + 2) % 3] = ((v + 0.5) * 2.0 / kCubeCells - 1.0) * depth;
    return c;
  }

 private:
  struct Measured {
    int step;  // of kStepDeg
    double range;
    int index;  // the cell's
  };
  // The nearest point the cloud measured in a measured cell.
  Eigen::Vector3d point_of(const Measured& m) const {
    return points_[static_cast<size_t>(nearest_[static_cast<size_t>(m.index)])].cast<double>();
  }

  // The first measured cell from unit direction d turning toward `axis`, in steps finer than
  // the cells at a face's edge, from step `first` to `last` (by default up to kRingSpacingDeg;
  // none: nothing measured); with `past_ring`, the first after an empty one (the ring measured
  // where the walk starts is passed).
  std::optional<Measured> first_measured(const Eigen::Vector3d& d, const Eigen::Vector3d& axis, bool past_ring = false,
                                         int first = 1, int last = kRingSteps) const {
    bool past = !past_ring;
    for (int k = first; k <= last; ++k) {
      const Eigen::Vector3d q = d + (k * kStepTangent) * axis;
      const std::optional<Cell> c = cell_of(q);
      if (!c) continue;
      if (!(depth_[static_cast<size_t>(c->index)] > 0.0f)) {
        past = true;
        continue;
      }
      if (!past) continue;
      const int face_axis = c->index / (kCubeCells * kCubeCells) / 2;
      return Measured{k, depth_[static_cast<size_t>(c->index)] * q.norm() / std::abs(q[face_axis]), c->index};
    }
    return std::nullopt;
  }

  // Whether a cell one or two steps of (du, dv) away on the cell's face, either way, measured.
  bool measured_nearby(int index, int du, int dv) const {
    const int u = index % kCubeCells, v = (index / kCubeCells) % kCubeCells;
    for (int k : {-2, -1, 1, 2}) {
      const int x = u + k * du, y = v + k * dv;
      if (x >= 0 && x < kCubeCells && y >= 0 && y < kCubeCells &&
          depth_[static_cast<size_t>(index + (y - v) * kCubeCells + (x - u))] > 0.0f)
        return true;
    }
    return false;
  }

  // [-1, 1] on the face to a cell column or row.
  static int cell_coordinate(double t) {
    return std::clamp(static_cast<int>(std::floor((t + 1.0) * 0.5 * kCubeCells)), 0, kCubeCells - 1);
  }

  static constexpr int kRingSteps = 20;  // the steps of a walk across kRingSpacingDeg
  static constexpr double kStepDeg = kRingSpacingDeg / kRingSteps;  // 0.15: finer than a cell at a face's edge (0.16)
  static inline const double kStepTangent = std::tan(kStepDeg * M_PI / 180.0);

  const std::vector<Eigen::Vector3f>& points_;
  std::vector<float> depth_;
  std::vector<int> nearest_;  // per cell, the index of its nearest point (-1: none)
  bool dense_ = false;  // a depth camera's cloud, not a lidar's rings (the constructor)
};

// The frame's depth image (or its cloud's cube) seen from the world: whether a point lies in
// front of (or behind) what the camera measured along its line of sight. A ray proves free only
// the space it crosses, but a query or carving value lands at a voxel centre up to 0.87 voxel
// away, which beside an edge seen at a grazing angle can lie inside the object: then its
// negative value rounds the edge off (random box rooms: bins clipping a box's vertical edge
// read the wall behind). Near the surface a centre gets a free-space value only if its pixel
// and their 8 neighbours (mixed pixels at silhouettes report the far side) all measured
// something farther. A frame whose image is not width x height pixels is rejected
// (std::invalid_argument), not read as a point cloud.
class DepthView {
 public:
  explicit DepthView(const Frame& frame)
      : frame_(frame), camera_T_world_(frame.world_T_camera.inverse()),
        image_(has_depth_image(frame)) {  // throws when the image is not width x height
    if (!image_) cube_ = std::make_unique<const CubeRangeImage>(frame.points_camera);
    else find_silhouettes();
  }

  // A world point as the camera sees it: its camera coordinates and its pixel (none outside
  // the image), or for a cloud its cell of the cube. One projection answers every question
  // about the point.
  struct Sight {
    Eigen::Vector3d camera;
    std::optional<Pixel> pixel;
    std::optional<CubeRangeImage::Cell> cell;
  };
  Sight sight(const Eigen::Vector3d& world) const {
    Sight s{camera_T_world_ * world, std::nullopt, std::nullopt};
    if (image_) s.pixel = pixel_of(frame_.intrinsics, frame_.width, frame_.height, s.camera);
    else s.cell = CubeRangeImage::cell_of(s.camera);
    return s;
  }

  // In the image, and every measured depth of its pixel and the 8 around it is farther (for a
  // cloud: at least one of its 9 cells measured, and all of them farther).
  bool seen_in_front(const Sight& s) const {
    if (s.cell) return cube_->farther_around(s.cell->index, s.cell->depth);
    if (!s.pixel) return false;
    const Pixel& px = *s.pixel;
    for (int y = std::max(px.v - 1, 0); y <= std::min(px.v + 1, frame_.height - 1); ++y)
      for (int x = std::max(px.u - 1, 0); x <= std::min(px.u + 1, frame_.width - 1); ++x) {
        const float d = depth_at(x, y);
        if (d > 0.0f && d <= s.camera.z()) return false;
      }
    return true;
  }

  bool has_image() const { return image_; }

  // Projects less than `pixels` inside the image's edge (or outside the image); a cloud has no
  // edge.
  bool at_edge(const Eigen::Vector3d& world, double pixels) const {
    if (!image_) return false;
    const std::optional<Eigen::Vector2d> p = projection(frame_.intrinsics, camera_T_world_ * world);
    if (!p) return false;
    const double inset = std::min(std::min(p->x() + 0.5, frame_.width - 0.5 - p->x()),
                                  std::min(p->y() + 0.5, frame_.height - 0.5 - p->y()));
    return inset < pixels;
  }

  // For a cloud, the world points of the next ring on one side of a ring's world-frame line
  // through `world` (CubeRangeImage::next_rings), and of the one after (add_second_ring); none
  // for an image.
  CubeRangeImage::NextRings next_rings(const Eigen::Vector3d& world, const Eigen::Vector3d& line, double side) const {
    CubeRangeImage::NextRings rings;
    if (!cube_) return rings;
    rings = cube_->next_rings(camera_T_world_ * world, camera_T_world_.linear() * line, side);
    if (rings.first) rings.first = frame_.world_T_camera * *rings.first;
    return rings;
  }
  void add_second_ring(CubeRangeImage::NextRings& rings) const {
    if (!cube_) return;
    cube_->add_second_ring(rings);
    if (rings.second) rings.second = frame_.world_T_camera * *rings.second;
  }

  // For a cloud, whether it measured around the point (CubeRangeImage::measured_around); an
  // image measured every pixel.
  bool measured_around(const Sight& s, double voxel) const {
    return !s.cell || cube_->measured_around(s.camera, s.cell->index, voxel);
  }

  // In the image, within a tile of kSilhouetteTile pixels (or a tile beside it) that holds a
  // silhouette: a pixel whose neighbour two pixels right or down measured farther or nearer by
  // over kSilhouetteJump of the nearer depth (at least of 1 m), or measured where it did not. One
  // byte read, a cheap test before a dearer one. A cloud answers true at once (a Sight would
  // find the point's cube cell, for nothing).
  bool near_silhouette(const Eigen::Vector3d& world) const {
    if (!image_) return true;
    const std::optional<Pixel> px = pixel_of(frame_.intrinsics, frame_.width, frame_.height, camera_T_world_ * world);
    if (!px) return false;
    return silhouette_tiles_[static_cast<size_t>(px->v / kSilhouetteTile) * tiles_across_ + px->u / kSilhouetteTile] !=
           0;
  }

  // Whether near_silhouette() may hold anywhere in a world box: false when the box's projection,
  // widened by a pixel, covers no silhouette tile, or lies outside the image. Exact as a
  // pre-test: in front of the camera a box projects inside the rectangle of its corners'
  // projections, and the pixel a margin covers rounding. A cloud, or a box reaching behind the
  // camera, answers true. One test per local leaf instead of a projection per local voxel.
  bool may_touch_silhouette(const Eigen::AlignedBox3d& world) const {
    if (!image_) return true;
    double u_min = INFINITY, u_max = -INFINITY, v_min = INFINITY, v_max = -INFINITY;
    for (int corner = 0; corner < 8; ++corner) {
      const std::optional<Eigen::Vector2d> p = projection(
          frame_.intrinsics, camera_T_world_ * world.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
      if (!p || !p->allFinite()) return true;
      u_min = std::min(u_min, p->x()), u_max = std::max(u_max, p->x());
      v_min = std::min(v_min, p->y()), v_max = std::max(v_max, p->y());
    }
    const double last_u = frame_.width - 1, last_v = frame_.height - 1;
    if (u_max + 1.0 < 0.0 || v_max + 1.0 < 0.0 || u_min - 1.0 > last_u || v_min - 1.0 > last_v) return false;
    auto tile = [](double pixel, double last) {
      return static_cast<int>(std::clamp(pixel, 0.0, last)) / kSilhouetteTile;
    };
    return silhouette_tiles_in(tile(std::floor(u_min - 1.0), last_u), tile(std::ceil(u_max + 1.0), last_u),
                               tile(std::floor(v_min - 1.0), last_v), tile(std::ceil(v_max + 1.0), last_v)) > 0;
  }

  // In the image, and its own pixel (or cell) measured a surface more than `margin` farther.
  bool seen_past(const Sight& s, double margin) const {
    const float d = measured_depth(s);
    return d > 0.0f && d > depth_of(s) + margin;
  }

  // In the image, and its own pixel (or cell) measured a surface more than `margin` nearer.
  bool seen_behind(const Sight& s, double margin) const {
    const float d = measured_depth(s);
    return d > 0.0f && d < depth_of(s) - margin;
  }

  // The world point that the point's pixel (or cell, at its centre) measured (none outside the
  // image or where nothing was measured).
  std::optional<Eigen::Vector3d> measured(const Sight& s) const {
    const double d = measured_depth(s);
    if (!(d > 0.0)) return std::nullopt;
    if (s.cell) return frame_.world_T_camera * CubeRangeImage::point(s.cell->index, d);
    const PinholeIntrinsics& k = frame_.intrinsics;
    const Eigen::Vector3d camera((s.pixel->u - k.cx) / k.fx * d, (s.pixel->v - k.cy) / k.fy * d, d);
    return frame_.world_T_camera * camera;
  }

 private:
  float depth_at(int u, int v) const { return frame_.depth[static_cast<size_t>(v) * frame_.width + u]; }
  // What the point's own pixel or cell measured (0: nothing, or outside the image).
  float measured_depth(const Sight& s) const {
    if (s.cell) return cube_->depth(s.cell->index);
    return s.pixel ? depth_at(s.pixel->u, s.pixel->v) : 0.0f;
  }
  // The point's own depth, as its pixel or cell measures depth.
  static double depth_of(const Sight& s) { return s.cell ? s.cell->depth : s.camera.z(); }

  static constexpr int kSilhouetteTile = 4;
  static constexpr float kSilhouetteJump = 0.05f;  // depth noise grows with depth; edges jump more
  static bool jumps(float a, float b) {  // without branches: `|`, not `||`
    return ((a > 0.0f) != (b > 0.0f)) | (std::abs(a - b) > kSilhouetteJump * std::max(1.0f, std::min(a, b)));
  }
  // The tiles holding a silhouette, each then marked where a tile beside it holds one: across
  // while the rows are found, then up and down, each pass in parallel over rows of tiles.
  void find_silhouettes() {
    const int w = frame_.width, h = frame_.height;
    tiles_across_ = (w + kSilhouetteTile - 1) / kSilhouetteTile;
    const size_t across = static_cast<size_t>(tiles_across_);
    const size_t down = static_cast<size_t>((h + kSilhouetteTile - 1) / kSilhouetteTile);
    std::vector<uint8_t> widened(across * down, 0);
    parallel_for_each_index(down, [&](size_t ty) {
      std::vector<uint8_t> own(across, 0);
      mark_silhouette_row(static_cast<int>(ty), own.data());
      uint8_t* row = &widened[ty * across];
      for (size_t tx = 0; tx < across; ++tx)
        row[tx] = own[tx] | (tx > 0 ? own[tx - 1] : 0) | (tx + 1 < across ? own[tx + 1] : 0);
    });
    silhouette_tiles_.assign(widened.size(), 0);
    parallel_for_each_index(down, [&](size_t ty) {
      uint8_t* row = &silhouette_tiles_[ty * across];
      for (size_t y = ty > 0 ? ty - 1 : 0; y <= std::min(ty + 1, down - 1); ++y)
        for (size_t tx = 0; tx < across; ++tx) row[tx] |= widened[y * across + tx];
    });
    count_silhouette_tiles(across, down);
  }
  // The silhouette tiles summed over every rectangle from the image's corner (a summed-area
  // table, one row and column of zeros first), so that a rectangle's count costs four reads.
  void count_silhouette_tiles(size_t across, size_t down) {
    tiles_before_.assign((across + 1) * (down + 1), 0);
    for (size_t ty = 0; ty < down; ++ty) {
      int32_t in_row = 0;
      for (size_t tx = 0; tx < across; ++tx) {
        in_row += silhouette_tiles_[ty * across + tx] != 0;
        tiles_before_[(ty + 1) * (across + 1) + tx + 1] = tiles_before_[ty * (across + 1) + tx + 1] + in_row;
      }
    }
  }
  // The silhouette tiles among tiles [tx0, tx1] x [ty0, ty1].
  int32_t silhouette_tiles_in(int tx0, int tx1, int ty0, int ty1) const {
    const size_t stride = static_cast<size_t>(tiles_across_) + 1;
    auto before = [&](int tx, int ty) {
      return tiles_before_[static_cast<size_t>(ty) * stride + static_cast<size_t>(tx)];
    };
    return before(tx1 + 1, ty1 + 1) - before(tx0, ty1 + 1) - before(tx1 + 1, ty0) + before(tx0, ty0);
  }
  // One row of tiles: every second pixel of every second row against the next such pixel right
  // and down (a step between two neighbours is a step between the two pixels around them), a
  // tile (its two pixels of the row) at a time. The last tile's last pixel meets the row's last
  // one, the last row meets itself.
  void mark_silhouette_row(int ty, uint8_t* tiles) const {
    static_assert(kSilhouetteTile == 4, "two compared pixels per tile row");
    const int w = frame_.width, h = frame_.height;
    for (int v = ty * kSilhouetteTile; v < std::min((ty + 1) * kSilhouetteTile, h); v += 2) {
      const float* row = &frame_.depth[static_cast<size_t>(v) * w];
      const float* below = v + 2 < h ? row + 2 * w : row;
      int tx = 0;
      for (; 4 * tx + 4 < w; ++tx) {
        const float* p = row + 4 * tx;
        const float* q = below + 4 * tx;
        tiles[tx] |= jumps(p[0], p[2]) | jumps(p[2], p[4]) | jumps(p[0], q[0]) | jumps(p[2], q[2]);
      }
      for (int u = 4 * tx; u < w; u += 2)
        tiles[tx] |= jumps(row[u], row[std::min(u + 2, w - 1)]) | jumps(row[u], below[u]);
    }
  }

  const Frame& frame_;
  Eigen::Isometry3d camera_T_world_;
  bool image_;
  std::vector<uint8_t> silhouette_tiles_;  // images only
  std::vector<int32_t> tiles_before_;      // count_silhouette_tiles
  int tiles_across_ = 0;
  // Frames without an image. (A std::optional here drew GCC 12's -Wmaybe-uninitialized on its
  // vector in the sanitizer build, a false report.)
  std::unique_ptr<const CubeRangeImage> cube_;
};

}  // namespace sonomap::gpdf
