// SPDX-License-Identifier: GPL-3.0-or-later
// Ghosts of moved objects and how fast a map clears them (docs/conventions.md "Moved-object
// ghosts"). A run feeds every evaluated frame in order: the true poses of the moving objects,
// the estimated circle and its truth, and the depth image with the TRUE camera pose. Per
// object the tracker keeps the places it occupied (cells of a grid), notes when the camera
// first sees through each vacated cell (its centre, or a ghost point read in it), and counts
// the ghost bins whose estimate point lies in a vacated cell. Pure: no I/O.
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace sonomap::eval {

// A moving object as the evaluator knows it: a name and the bounding box of its shape in its
// own frame (the place it takes at a pose is this box at that pose).
struct MovingObjectShape {
  std::string name;
  Eigen::AlignedBox3d box;
};

struct MovedGhostsConfig {
  // The ghost tolerance of the metrics (metrics.ghost_tolerance): a bin is a ghost when its
  // estimate is nearer than the truth by more than this (or the truth is empty); a place
  // counts as the object's when it lies within this of the object's box; the camera sees
  // through a place when its depth reading lies beyond it by more than this.
  double tolerance = 0.10;
  double ground_z = 0.0;
  RasterConfig raster;  // the band: only places at the circle's heights are kept
  // Edge of the grid's cubic cells: half the tolerance, at least 2 cm.
  double cell_size() const;
  // Throws std::invalid_argument naming the field for a non-finite or negative tolerance or
  // an invalid raster config.
  void validate() const;
};

// One object's readings at one frame: ghost bins whose estimate point lies in a place the
// object has left, which the camera has seen empty (seen) or not yet (unseen).
struct MovedObjectReadings {
  int seen = 0;
  int unseen = 0;
};

struct MovedGhostFrame {
  std::vector<MovedObjectReadings> objects;  // one per object, in the tracker's order
  int bins = 0;       // ghost bins reading a place some object has left (each bin once)
  int seen_bins = 0;  // those among them reading a place the camera has seen empty
};

// One object over the whole run.
struct MovedObjectClearing {
  std::string name;
  // First evaluated frame at which the camera saw through a place the object had left; none
  // when it never did (the object never moved, or its old place stayed out of sight).
  std::optional<int> seen_empty_frame;
  // The worst, over the cells of its old places, of (first evaluated frame after the last
  // reading of the cell) - (frame the cell was seen empty); 0 when no bin read a seen-empty
  // cell. None when never seen empty, or when bins still read a seen-empty cell at the end.
  std::optional<int> clearing_frames;
  int ghost_bins_at_end = 0;         // bins reading seen-empty places at the final frame
  int unseen_ghost_bins_at_end = 0;  // bins reading places the camera has not seen empty
  int max_ghost_bins = 0;            // the most bins reading seen-empty places in one frame
  int ghost_frames = 0;              // evaluated frames with at least one such bin
  bool cleared() const { return clearing_frames.has_value(); }
};

class MovedGhosts {
 public:
  // Throws std::invalid_argument for an invalid config or an empty box.
  MovedGhosts(std::vector<MovingObjectShape> objects, const MovedGhostsConfig& config);

  // One evaluated frame (frame indices strictly increasing). `poses`: per object its true
  // world_T_object at the frame's time, none while it is not in the scene. `estimate` and
  // `truth`: the circle and its exact truth. `depth`: the frame's depth image (its intrinsics;
  // no seeing through without valid ones), `world_T_camera`: the TRUE camera pose.
  // Throws std::invalid_argument for a wrong number of poses, circles of different sizes, a
  // depth image of the wrong size or a frame index not after the previous one.
  MovedGhostFrame add_frame(int frame, const std::vector<std::optional<Eigen::Isometry3d>>& poses,
                            const Circle& estimate, const Circle& truth, const Frame& depth,
                            const Eigen::Isometry3d& world_T_camera);

  // Per object, in the order given, the figures so far.
  std::vector<MovedObjectClearing> results() const;
  int object_count() const { return static_cast<int>(objects_.size()); }

 private:
  struct Cell {
    Eigen::Vector3d centre;
    int occupied_at = -1;    // last evaluated frame the object's place held it
    int seen_empty_at = -1;  // frame the camera first saw through it since it was vacated
  };
  struct Tracked {
    MovingObjectShape shape;
    std::vector<Cell> cells;
    std::unordered_map<std::uint64_t, int> index;  // grid key -> cells[i]
    std::vector<int> held;  // the cells its place holds at held_pose
    std::optional<Eigen::Isometry3d> held_pose;
    MovedObjectClearing result;
    int worst_age = -1;  // this frame: max (frame - seen_empty_at) over read cells; -1: none
    int open_worst = 0;  // max over earlier frames of (next frame - frame + worst age there)
  };
  void check_input(int frame, std::size_t poses, const Circle& estimate, const Circle& truth,
                   const Frame& depth) const;
  void read_bin(const Eigen::Vector3d& q, int frame, const Frame& depth, const Eigen::Isometry3d& camera_T_world,
                MovedGhostFrame& out);
  void occupy(Tracked& object, const Eigen::Isometry3d& pose, int frame);
  void place(Tracked& object, const Eigen::Isometry3d& pose);
  void look_through(Tracked& object, const Frame& depth, const Eigen::Isometry3d& camera_T_world,
                    int frame);
  bool seen_through(const Eigen::Vector3d& world_point, const Frame& depth,
                    const Eigen::Isometry3d& camera_T_world) const;
  void mark_seen(Tracked& object, Cell& cell, int frame);
  std::uint64_t key_of(const Eigen::Vector3d& p) const;

  MovedGhostsConfig config_;
  double cell_ = 0.0;
  std::vector<Tracked> objects_;
  int last_frame_ = -1;
};

}  // namespace sonomap::eval
