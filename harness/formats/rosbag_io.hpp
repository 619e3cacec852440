// SPDX-License-Identifier: GPL-3.0-or-later
// ROS1 bags in and out, with Debian's rosbag_storage. Reading streams the depth topic one
// message at a time (never the whole bag); the pose topic (small messages) is read at open.
// ROS types stay inside harness/rosbag/rosbag_io.cpp, a library loaded the first time a bag is
// read or written (modules.hpp): nothing else includes a ROS header.
#pragma once

#include "harness/formats/sequence_io.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::harness {

// The bag reader of a sequence file's ros1_bag source: depth (sensor_msgs/Image, 16UC1 or
// 32FC1, or sensor_msgs/PointCloud2 with float32 x, y, z in the camera optical frame: an
// organised cloud gives a depth image, an unorganised one points only), intrinsics (given, or the first sensor_msgs/CameraInfo on camera.info_topic), poses
// (geometry_msgs/TransformStamped or PoseStamped), each depth frame taking the pose nearest in
// header time (or interpolated) within time.tolerance. Throws InputError naming the bag, the
// topic and the message index for a truncated bag, a missing topic, a wrong message type,
// stamps out of order, or a frame with no pose.
std::unique_ptr<RecordReader> open_rosbag_reader(const SequenceSpec& spec);

// The topics of a bag with their message type and count, in topic order (what `rosbag info`
// shows). Throws InputError naming the bag when it cannot be read.
struct BagTopic {
  std::string topic, type;
  long long messages = 0;
};
std::vector<BagTopic> list_rosbag_topics(const std::filesystem::path& file);

// A ROS1 bag being written (open_rosbag_writer). Stamps are seconds (> 0).
class RosbagWriter {
 public:
  virtual ~RosbagWriter() = default;

  // sensor_msgs/Image: depth in metres as 32FC1, or as 16UC1 units of 1/units_per_metre
  // (rounded; a depth 16 bits cannot hold becomes 0). `received`: the bag's record time (a
  // bag is ordered by it), 0 for the stamp.
  virtual void depth(const std::string& topic, double stamp, const std::string& frame_id, int width,
                     int height, const std::vector<float>& metres, double units_per_metre = 0.0,
                     double received = 0.0) = 0;
  virtual void camera_info(const std::string& topic, double stamp, const std::string& frame_id,
                           const sim::CameraSpec& camera) = 0;
  virtual void transform(const std::string& topic, double stamp, const std::string& parent,
                         const std::string& child, const Eigen::Isometry3d& parent_T_child) = 0;
  // sensor_msgs/PointCloud2 of a depth image: organised (height rows of width points; x, y, z
  // float32 in the camera optical frame, NaN where there is no return, as RGB-D drivers publish
  // it), or unorganised (one row of the valid points only).
  virtual void point_cloud(const std::string& topic, double stamp, const std::string& frame_id,
                           const sim::CameraSpec& camera, const std::vector<float>& metres,
                           bool organised = true) = 0;
  // tf2_msgs/TFMessage with one transform per (parent, child, parent_T_child).
  struct Link {
    std::string parent, child;
    Eigen::Isometry3d parent_T_child;
  };
  virtual void tf(const std::string& topic, double stamp, const std::vector<Link>& links) = 0;
  virtual void close() = 0;
};

// How a bag's chunks are written: as they are (rosbag's default), or compressed as rosbag does.
enum class BagCompression { None, Lz4, Bz2 };

// Creates (or replaces) the bag `file`. Throws std::runtime_error when it cannot.
std::unique_ptr<RosbagWriter> open_rosbag_writer(const std::filesystem::path& file,
                                                 BagCompression compression = BagCompression::None);

}  // namespace sonomap::harness
