// SPDX-License-Identifier: GPL-3.0-or-later
// A sequence file (sequence.yaml) says how to read a recording: where the depth frames are and
// how they are encoded, the camera, where the poses come from and in which format, where the
// camera sits on the listener, which way is up in the recording's world and where its floor
// is, and how depth and pose stamps are matched. Reference: docs/real-data.md.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>

namespace sonomap::harness {

enum class SequenceSource { Tum, Folder, Ros1Bag };
// 16UC1 (units of 1/scale metre), 32FC1 (metres), sensor_msgs/PointCloud2 (metres, bags only)
enum class DepthEncoding { Mono16, Float32, PointCloud2 };
enum class PoseFormat { Tum, Matrix4x4, Kitti, Topic };

struct SequenceSpec {
  std::filesystem::path file;  // the sequence file itself (errors name it)
  std::string name;
  SequenceSource source = SequenceSource::Tum;
  std::filesystem::path path;  // the TUM folder, the frame folder or the bag

  // Folder: frame i's depth file is `depth_pattern` with its run of '#' replaced by
  // first + i, zero-padded to the run's length; `count` frames.
  std::string depth_pattern;
  int first = 0;
  int count = 0;
  std::string depth_topic;  // ROS1 bag: sensor_msgs/Image or PointCloud2
  DepthEncoding encoding = DepthEncoding::Mono16;
  double depth_scale = 1.0;  // 16UC1 units per metre (millimetres: 1000)

  sim::CameraSpec camera;  // intrinsics and size unused when camera_info_topic is set
  std::string camera_info_topic;

  PoseFormat pose_format = PoseFormat::Tum;
  std::string pose_pattern;  // matrix4x4: one camera-to-world file per frame, like depth_pattern
  std::filesystem::path pose_file;  // kitti: one 3x4 row per frame
  std::string pose_topic;    // geometry_msgs/TransformStamped or PoseStamped
  // The recorded poses are of this frame (e.g. a tracking marker); the camera's pose is
  // pose * pose_T_camera. Identity: the poses are the camera's.
  Eigen::Isometry3d pose_T_camera = Eigen::Isometry3d::Identity();

  // The recording's world axis that points up (a unit axis, +-x, +-y or +-z) and the floor:
  // its height along that axis, or the listener's height above it at the first frame.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  bool up_given = false;
  std::optional<double> floor;
  std::optional<double> listener_height;
  // floor: auto: the floor plane found (RANSAC) in the first `floor_frames` frames sets the up
  // axis (its normal; `up`, when given, or else the first camera's up is the starting guess,
  // within 30 degrees) and the floor.
  bool auto_floor = false;
  int floor_frames = 10;

  // Ground truth: a reference point cloud or mesh of the scene (PLY, OBJ, STL), in the frame
  // world_T_truth places in the recording's world. Empty: the recording has no truth.
  std::filesystem::path truth_file;
  bool truth_is_mesh = false;
  Eigen::Isometry3d world_T_truth = Eigen::Isometry3d::Identity();

  double time_tolerance = 0.02;  // seconds between a depth frame and its pose
  bool interpolate = false;      // bags: interpolate between the poses around a frame
};

// True when `file` is a sequence file: named sequence.yaml, or a YAML map whose top-level key
// is `sequence`. Never throws (an unreadable file is "not a sequence file").
bool is_sequence_file(const std::filesystem::path& file);

// Reads and checks a sequence file: every key known, every number in range, what the source
// needs present. Throws InputError naming the file, line and key.
SequenceSpec load_sequence_spec(const std::filesystem::path& file);

// Frame index -> file name for a pattern with one run of '#'.
std::string expand_frame_pattern(const std::string& pattern, long long number);

}  // namespace sonomap::harness
