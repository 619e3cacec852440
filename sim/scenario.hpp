// SPDX-License-Identifier: GPL-3.0-or-later
// A scenario as plain data: what the world holds, how the sensor moves and what it is.
// The harness parses YAML into this; sim/ turns it into a World and a Sensor.
// Units: metres, seconds, radians in code (the YAML says degrees; the parser converts).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::sim {

// Indexed triangle mesh in its own frame.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
};

// How poses between keyframes are interpolated. Named explicitly in every scenario.
enum class Interpolation {
  LinearSlerp,  // position linear in time, orientation slerp
};

struct Keyframe {
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

struct TrajectorySpec {
  Interpolation interpolation = Interpolation::LinearSlerp;
  std::vector<Keyframe> keyframes;  // strictly increasing times, at least one
};

// The listener's head, for rendering only: the sensor and the rasters stay on the body. Yaw
// and pitch are linear in time between keyframes (no wrap: a keyframe yaw of 270 after 0 turns
// three quarters left), held before the first and after the last.
struct HeadKeyframe {
  double time = 0.0;
  double yaw_deg = 0.0;    // left positive
  double pitch_deg = 0.0;  // positive tilts the face down (recorded; the sweep is horizontal)
};
struct HeadSpec {
  bool absolute = false;  // yaw in the world; otherwise relative to the body's heading
  std::vector<HeadKeyframe> keyframes;  // strictly increasing times, at least one
  HeadKeyframe at(double t) const;      // the interpolated yaw and pitch at time t
};

// A shape in the scene before triangulation. Kept so that tests and ground truth can use
// closed forms; the simulator only ever sees the triangulated mesh.
struct PrimitiveSpec {
  enum class Kind { Room, Box, Cylinder, Sphere, Plane, Mesh };
  Kind kind = Kind::Box;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();  // Room/Box: full extents; Plane: x, y extents
  double radius = 0.5;                              // Cylinder, Sphere
  double height = 1.0;                              // Cylinder (vertical, base at z = 0 of its frame)
  int segments = 64;                                // Cylinder/Sphere tessellation
  std::string mesh_path;                            // Mesh: file the harness loaded
};

struct StaticObject {
  std::string name;
  PrimitiveSpec shape;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world_T_object
  TriangleMesh mesh;  // triangulated, in the object frame
};

struct MovingObject {
  std::string name;
  PrimitiveSpec shape;
  TriangleMesh mesh;          // in the object frame
  TrajectorySpec trajectory;  // world_T_object over time
  double appear_time = -std::numeric_limits<double>::infinity();
  double disappear_time = std::numeric_limits<double>::infinity();
};

struct CameraSpec {
  int width = 640;
  int height = 480;
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;  // Kinect v1 defaults
  double min_range = 0.3;  // metres, along the ray's z-depth
  double max_range = 5.0;
  double rate_hz = 30.0;
  // Camera optical frame on the body (x forward, y left, z up). Default: head-mounted at the
  // body origin, looking along body x: optical z = body x, optical x = -body y, optical y = -body z.
  Eigen::Isometry3d body_T_camera = default_body_T_camera();

  static Eigen::Isometry3d default_body_T_camera() {
    Eigen::Matrix3d r;
    r << 0, 0, 1,
        -1, 0, 0,
         0, -1, 0;
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = r;
    return t;
  }
};

struct NoiseSpec {
  enum class Model { None, Kinect };
  Model model = Model::None;
  // Stages of the Kinect model (Nguyen, Izadi, Lovell 2012; Khoshelham & Elberink 2012).
  bool lateral = true;
  bool axial = true;
  bool quantisation = true;
  bool grazing_invalidation = true;
  bool edge_invalidation = true;
  double dropout = 0.0;              // probability a valid pixel is dropped
  double baseline = 0.075;           // metres, Kinect v1
  double disparity_step = 0.125;     // pixels (1/8)
  double edge_threshold = 0.1;       // metres: depth jump to a neighbour that marks an edge
  double grazing_angle = 1.3962634015954636;  // radians (80 deg): beyond it, no return
};

struct LocalisationSpec {
  // Pose handed to the mapper = true pose, optionally with seeded noise and drift.
  double translation_noise = 0.0;    // metres, per-frame white noise (sigma)
  double yaw_noise = 0.0;            // radians, per-frame white noise (sigma)
  double translation_drift = 0.0;    // metres / sqrt(second), random walk
  double yaw_drift = 0.0;            // radians / sqrt(second), random walk
  double time_offset = 0.0;          // seconds: the pose is taken at (frame time + offset)
};

struct Scenario {
  std::string name;
  std::string source_path;  // the YAML file it came from (for messages)
  double ground_z = 0.0;
  std::vector<StaticObject> statics;
  std::vector<MovingObject> movers;
  CameraSpec camera;
  NoiseSpec noise;
  LocalisationSpec localisation;
  TrajectorySpec body;  // world_T_body over time
  std::optional<HeadSpec> head;  // none: the head follows the body
  int frames = 1;
  std::uint64_t seed = 1;
};

}  // namespace sonomap::sim
