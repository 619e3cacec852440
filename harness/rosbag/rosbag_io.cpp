// SPDX-License-Identifier: GPL-3.0-or-later
// libsonomap_rosbag_io.so: ROS1 bags in and out with Debian's rosbag_storage, loaded on demand
// (harness/formats/modules.hpp). Everything here has internal linkage but the entry point:
// the formats library's functions of the same names call in through the table.
#include "harness/formats/modules.hpp"
#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/rosbag_wire.hpp"
#include "harness/support/errors.hpp"

#include <bzlib.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <roslz4/lz4s.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// The wire format each message type is checked against (a type not listed does not compile).
template <typename T>
struct MessageKind;
template <>
struct MessageKind<sensor_msgs::Image> : std::integral_constant<BagMessageKind, BagMessageKind::Image> {};
template <>
struct MessageKind<sensor_msgs::PointCloud2>
    : std::integral_constant<BagMessageKind, BagMessageKind::PointCloud2> {};
template <>
struct MessageKind<sensor_msgs::CameraInfo>
    : std::integral_constant<BagMessageKind, BagMessageKind::CameraInfo> {};
template <>
struct MessageKind<geometry_msgs::TransformStamped>
    : std::integral_constant<BagMessageKind, BagMessageKind::TransformStamped> {};
template <>
struct MessageKind<geometry_msgs::PoseStamped>
    : std::integral_constant<BagMessageKind, BagMessageKind::PoseStamped> {};

// Uncompresses a chunk's data as rosbag does (bzip2, or roslz4's stream format), for the
// checks of the chunk's records before rosbag reads them (check_bag_records).
bool inflate_chunk(const std::string& compression, const std::string& packed, std::string& out) {
  if (packed.size() > std::numeric_limits<unsigned int>::max()) return false;
  // Both libraries take the input as char* but only read it: no copy of the chunk for them.
  char* in = const_cast<char*>(packed.data());
  unsigned int size = static_cast<unsigned int>(out.size());
  const auto in_size = static_cast<unsigned int>(packed.size());
  if (compression == "lz4")
    return roslz4_buffToBuffDecompress(in, in_size, out.data(), &size) == ROSLZ4_OK && size == out.size();
  if (compression == "bz2")
    return BZ2_bzBuffToBuffDecompress(out.data(), &size, in, in_size, 0, 0) == BZ_OK && size == out.size();
  return false;
}

// The bag, opened for reading, with errors that name it and the topic.
class BagFile {
 public:
  explicit BagFile(const fs::path& file) : file_(file) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) throw InputError(file.string(), 0, "", "missing or not a regular file");
    check_bag_records(file, inflate_chunk);
    try {
      bag_.open(file.string(), rosbag::bagmode::Read);
    } catch (const ros::Exception& e) {
      throw InputError(file.string(), 0, "",
                       std::string("cannot read the ROS1 bag (truncated, unindexed or not a bag: "
                                   "try 'rosbag reindex'): ") + e.what());
    }
  }
  rosbag::Bag& bag() { return bag_; }
  const fs::path& file() const { return file_; }

  // Fails unless `topic` is in the bag with one of `types`.
  void require(const std::string& topic, const std::vector<std::string>& types) {
    rosbag::View all(bag_);
    std::string present;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      if (c->topic == topic) {
        if (std::find(types.begin(), types.end(), c->datatype) != types.end()) return;
        fail(topic, 0, "message 0 is a " + c->datatype + "; expected " + join(types));
      }
      present += "\n  " + c->topic + " (" + c->datatype + ")";
    }
    fail(topic, -1, "no such topic in the bag; it has:" + (present.empty() ? std::string(" none") : present));
  }
  [[noreturn]] void fail(const std::string& topic, long long index, const std::string& what) const {
    throw InputError(file_.string() + ": topic " + topic +
                     (index >= 0 ? ", message " + std::to_string(index) : std::string()) + ": " + what);
  }
  // Message `index` of a View, as T (null: it is another type), with read errors named. Its
  // bytes are checked (bag_message_fits) before ROS deserialises them.
  template <typename T>
  boost::shared_ptr<T> instantiate(const rosbag::MessageInstance& m, long long index) const {
    if (!m.isType<T>()) return nullptr;
    auto message = boost::make_shared<T>();
    try {
      const std::uint32_t size = m.size();  // each call reads the record's header again
      if (size > kMaxBagMessageBytes)
        fail(m.getTopic(), index, "the message claims " + std::to_string(size) + " bytes (corrupt bag)");
      std::vector<std::uint8_t>& bytes = message_bytes_;
      bytes.resize(size);
      ros::serialization::OStream out(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
      m.write(out);
      if (!bag_message_fits(MessageKind<T>::value, bytes.data(), bytes.size()))
        fail(m.getTopic(), index, "a length in the message runs past its end (corrupt bag)");
      ros::serialization::IStream in(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
      ros::serialization::deserialize(in, *message);
    } catch (const ros::Exception& e) {
      fail(m.getTopic(), index, std::string("cannot read the message (truncated bag?): ") + e.what());
    }
    return message;
  }

 private:
  static std::string join(const std::vector<std::string>& words) {
    std::string out;
    for (const auto& w : words) out += (out.empty() ? "" : " or ") + w;
    return out;
  }
  fs::path file_;
  rosbag::Bag bag_;
  mutable std::vector<std::uint8_t> message_bytes_;  // reused: a depth image is a megabyte
};

struct StampedPose {
  double time;
  Eigen::Isometry3d pose;
};

Eigen::Isometry3d isometry(const geometry_msgs::Point& p, const geometry_msgs::Quaternion& q) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.x, p.y, p.z);
  return t;
}

// Poses of the topic (TransformStamped or PoseStamped), in order; out-of-order stamps fail.
std::vector<StampedPose> read_poses(BagFile& bag, const std::string& topic) {
  bag.require(topic, {"geometry_msgs/TransformStamped", "geometry_msgs/PoseStamped"});
  rosbag::View view(bag.bag(), rosbag::TopicQuery(topic));
  std::vector<StampedPose> poses;
  long long index = 0;
  for (const rosbag::MessageInstance& m : view) {
    StampedPose stamped{};
    if (const auto t = bag.instantiate<geometry_msgs::TransformStamped>(m, index)) {
      geometry_msgs::Point p;
      p.x = t->transform.translation.x, p.y = t->transform.translation.y, p.z = t->transform.translation.z;
      stamped = {t->header.stamp.toSec(), isometry(p, t->transform.rotation)};
    } else if (const auto s = bag.instantiate<geometry_msgs::PoseStamped>(m, index)) {
      stamped = {s->header.stamp.toSec(), isometry(s->pose.position, s->pose.orientation)};
    } else {
      bag.fail(topic, index, "is a " + m.getDataType() + "; expected geometry_msgs/TransformStamped");
    }
    if (!stamped.pose.matrix().allFinite()) bag.fail(topic, index, "the pose is not finite");
    if (!poses.empty() && stamped.time < poses.back().time)
      bag.fail(topic, index, "header stamp " + std::to_string(stamped.time) + " is before the previous one (" +
                                 std::to_string(poses.back().time) + "): stamps must be in order");
    poses.push_back(stamped);
    ++index;
  }
  return poses;
}

// The pose at time t: nearest within `tolerance`, or interpolated between the poses around t
// when both are within it. nullopt when there is none.
std::optional<Eigen::Isometry3d> pose_at(const std::vector<StampedPose>& poses, double t,
                                         double tolerance, bool interpolate) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const StampedPose& p, double time) { return p.time < time; });
  const StampedPose* next = after != poses.end() ? &*after : nullptr;
  const StampedPose* prev = after != poses.begin() ? &*(after - 1) : nullptr;
  const bool next_ok = next && next->time - t <= tolerance;
  const bool prev_ok = prev && t - prev->time <= tolerance;
  if (interpolate && next_ok && prev_ok && next->time > prev->time) {
    const double s = (t - prev->time) / (next->time - prev->time);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond(prev->pose.linear())
                        .slerp(s, Eigen::Quaterniond(next->pose.linear())).toRotationMatrix();
    pose.translation() = (1.0 - s) * prev->pose.translation() + s * next->pose.translation();
    return pose;
  }
  if (next_ok && (!prev_ok || next->time - t < t - prev->time)) return next->pose;
  if (prev_ok) return prev->pose;
  return std::nullopt;
}

sim::CameraSpec camera_from_info(BagFile& bag, const std::string& topic, sim::CameraSpec camera) {
  bag.require(topic, {"sensor_msgs/CameraInfo"});
  rosbag::View view(bag.bag(), rosbag::TopicQuery(topic));
  const auto info = bag.instantiate<sensor_msgs::CameraInfo>(*view.begin(), 0);
  if (!info) bag.fail(topic, 0, "is not a sensor_msgs/CameraInfo");
  const double fx = info->K[0], fy = info->K[4], cx = info->K[2], cy = info->K[5];
  const bool ok = info->width >= 1 && info->width <= 16384 && info->height >= 1 && info->height <= 16384 &&
                  fx >= 1.0 && fx <= 1e5 && fy >= 1.0 && fy <= 1e5 && std::isfinite(cx) && std::isfinite(cy);
  if (!ok) bag.fail(topic, 0, "size or intrinsics K out of range (width, height 1..16384; fx, fy 1..1e5)");
  camera.width = static_cast<int>(info->width);
  camera.height = static_cast<int>(info->height);
  camera.fx = fx, camera.fy = fy, camera.cx = cx, camera.cy = cy;
  return camera;
}

class BagReader final : public RecordReader {
 public:
  explicit BagReader(const SequenceSpec& spec) : spec_(spec), bag_(spec.path) {
    camera_ = spec.camera_info_topic.empty() ? spec.camera
                                             : camera_from_info(bag_, spec.camera_info_topic, spec.camera);
    poses_ = read_poses(bag_, spec.pose_topic);
    bag_.require(spec.depth_topic, {cloud() ? "sensor_msgs/PointCloud2" : "sensor_msgs/Image"});
    view_ = std::make_unique<rosbag::View>(bag_.bag(), rosbag::TopicQuery(spec.depth_topic));
    count_ = static_cast<int>(view_->size());
    rewind();
  }
  int count() const override { return count_; }
  const sim::CameraSpec& camera() const override { return camera_; }
  DepthRecord read(int i) override {
    if (i < next_) rewind();
    for (; next_ < i; ++next_) ++it_;  // skipped messages are not deserialised
    DepthRecord record = cloud() ? decode_cloud(message<sensor_msgs::PointCloud2>(i), i)
                                 : decode(message<sensor_msgs::Image>(i), i);
    ++it_, ++next_;
    if (i > 0 && record.time < last_stamp_)
      bag_.fail(spec_.depth_topic, i, "header stamp " + std::to_string(record.time) +
                                          " is before the previous one: stamps must be in order");
    last_stamp_ = record.time;
    const auto pose = pose_at(poses_, record.time, spec_.time_tolerance, spec_.interpolate);
    if (!pose)
      bag_.fail(spec_.depth_topic, i, "no pose on " + spec_.pose_topic + " within " +
                                          std::to_string(spec_.time_tolerance) + " s of stamp " +
                                          std::to_string(record.time));
    record.world_T_camera = *pose;
    return record;
  }

 private:
  bool cloud() const { return spec_.encoding == DepthEncoding::PointCloud2; }
  template <typename T>
  const T& message(int i) {
    current_ = bag_.instantiate<T>(*it_, i);
    if (!current_) bag_.fail(spec_.depth_topic, i, "is a " + it_->getDataType() + "; expected " +
                                                       ros::message_traits::datatype<T>());
    return *boost::static_pointer_cast<T>(current_);
  }
  void rewind() {
    it_ = view_->begin();
    next_ = 0;
  }
  DepthRecord decode(const sensor_msgs::Image& image, int i) const {
    const bool mono16 = spec_.encoding == DepthEncoding::Mono16;
    const std::string expected = mono16 ? "16UC1" : "32FC1";
    if (image.encoding != expected && !(mono16 && image.encoding == "mono16"))
      bag_.fail(spec_.depth_topic, i, "encoding " + image.encoding + ", but the sequence file says " + expected);
    if (static_cast<int>(image.width) != camera_.width || static_cast<int>(image.height) != camera_.height)
      bag_.fail(spec_.depth_topic, i, "image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                          ", the camera " + std::to_string(camera_.width) + "x" + std::to_string(camera_.height));
    const std::size_t bytes = mono16 ? 2 : 4;
    if (image.is_bigendian || image.step != image.width * bytes || image.data.size() != image.step * image.height)
      bag_.fail(spec_.depth_topic, i, "row step or data size does not match a dense little-endian image");
    DepthRecord record;
    record.time = image.header.stamp.toSec();
    record.width = camera_.width;
    record.height = camera_.height;
    const std::size_t n = static_cast<std::size_t>(record.width) * record.height;
    if (mono16) {
      std::vector<std::uint16_t> units(n);
      std::memcpy(units.data(), image.data.data(), n * bytes);
      record.depth = depth_from_units(units, spec_.depth_scale);
    } else {
      std::vector<float> metres(n);
      std::memcpy(metres.data(), image.data.data(), n * bytes);
      record.depth.assign(metres.begin(), metres.end());
    }
    return record;
  }
  // Float32 x, y, z in the camera optical frame: the cloud's finite points, and for an organised
  // cloud (the camera's rows) the depth image of their z as well.
  DepthRecord decode_cloud(const sensor_msgs::PointCloud2& cloud, int i) const {
    std::array<int, 3> offset{-1, -1, -1};
    for (const sensor_msgs::PointField& f : cloud.fields)
      for (int axis = 0; axis < 3; ++axis)
        if (f.name == std::string(1, static_cast<char>('x' + axis)) && f.datatype == sensor_msgs::PointField::FLOAT32)
          offset[axis] = static_cast<int>(f.offset);
    const std::size_t points = static_cast<std::size_t>(cloud.width) * cloud.height;
    const bool fits = *std::min_element(offset.begin(), offset.end()) >= 0 &&
                      *std::max_element(offset.begin(), offset.end()) + 4 <= static_cast<int>(cloud.point_step) &&
                      cloud.row_step >= cloud.width * cloud.point_step &&
                      cloud.data.size() >= static_cast<std::size_t>(cloud.row_step) * cloud.height;
    if (cloud.is_bigendian || !fits)
      bag_.fail(spec_.depth_topic, i, "expected a little-endian cloud with float32 fields x, y, z inside "
                                      "point_step and data of row_step x height bytes");
    const auto at = [&](std::size_t row, std::size_t col, int axis) {
      float v = 0.0f;
      std::memcpy(&v, &cloud.data[row * cloud.row_step + col * cloud.point_step + offset[axis]], 4);
      return v;
    };
    DepthRecord record;
    record.time = cloud.header.stamp.toSec();
    if (cloud.height <= 1) {
      for (std::size_t k = 0; k < points; ++k) {
        const Eigen::Vector3f p(at(0, k, 0), at(0, k, 1), at(0, k, 2));
        if (p.allFinite() && p.z() > 0.0f) record.points.push_back(p);
      }
      return record;
    }
    if (static_cast<int>(cloud.width) != camera_.width || static_cast<int>(cloud.height) != camera_.height)
      bag_.fail(spec_.depth_topic, i, "organised cloud is " + std::to_string(cloud.width) + "x" +
                                          std::to_string(cloud.height) + ", the camera " + std::to_string(camera_.width) +
                                          "x" + std::to_string(camera_.height));
    record.width = camera_.width;
    record.height = camera_.height;
    record.depth.resize(points);
    for (std::size_t k = 0; k < points; ++k) {
      const Eigen::Vector3f p(at(k / cloud.width, k % cloud.width, 0), at(k / cloud.width, k % cloud.width, 1),
                              at(k / cloud.width, k % cloud.width, 2));
      const bool valid = p.allFinite() && p.z() > 0.0f;
      record.depth[k] = valid ? p.z() : 0.0;
      if (valid) record.points.push_back(p);
    }
    return record;
  }

  SequenceSpec spec_;
  BagFile bag_;
  sim::CameraSpec camera_;
  std::vector<StampedPose> poses_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  boost::shared_ptr<void> current_;  // the message being decoded
  int next_ = 0;
  int count_ = 0;
  double last_stamp_ = 0.0;
};

std::unique_ptr<RecordReader> open_reader(const SequenceSpec& spec) {
  return std::make_unique<BagReader>(spec);
}

std::vector<BagTopic> list_topics(const fs::path& file) {
  BagFile bag(file);
  std::vector<BagTopic> topics;
  rosbag::View all(bag.bag());
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    rosbag::View one(bag.bag(), rosbag::TopicQuery(c->topic));
    topics.push_back({c->topic, c->datatype, static_cast<long long>(one.size())});
  }
  std::sort(topics.begin(), topics.end(), [](const BagTopic& a, const BagTopic& b) { return a.topic < b.topic; });
  topics.erase(std::unique(topics.begin(), topics.end(), [](const BagTopic& a, const BagTopic& b) { return a.topic == b.topic; }),
               topics.end());
  return topics;
}

class BagWriter final : public RosbagWriter {
 public:
  BagWriter(const fs::path& file, BagCompression compression) {
    try {
      bag_.open(file.string(), rosbag::bagmode::Write);
      bag_.setCompression(compression == BagCompression::Lz4   ? rosbag::compression::LZ4
                          : compression == BagCompression::Bz2 ? rosbag::compression::BZ2
                                                               : rosbag::compression::Uncompressed);
    } catch (const ros::Exception& e) {
      throw std::runtime_error("cannot create " + file.string() + ": " + e.what());
    }
  }
  void depth(const std::string& topic, double stamp, const std::string& frame_id, int width, int height,
             const std::vector<float>& metres, double units_per_metre, double received) override;
  void camera_info(const std::string& topic, double stamp, const std::string& frame_id,
                   const sim::CameraSpec& camera) override;
  void transform(const std::string& topic, double stamp, const std::string& parent,
                 const std::string& child, const Eigen::Isometry3d& parent_T_child) override;
  void point_cloud(const std::string& topic, double stamp, const std::string& frame_id,
                   const sim::CameraSpec& camera, const std::vector<float>& metres, bool organised) override;
  void tf(const std::string& topic, double stamp, const std::vector<Link>& links) override;
  void close() override { bag_.close(); }

 private:
  rosbag::Bag bag_;
};

void BagWriter::depth(const std::string& topic, double stamp, const std::string& frame_id, int width,
                      int height, const std::vector<float>& metres, double units_per_metre,
                      double received) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.header.frame_id = frame_id;
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  image.is_bigendian = 0;
  if (units_per_metre > 0.0) {
    image.encoding = "16UC1";
    std::vector<std::uint16_t> units(metres.size());
    for (std::size_t i = 0; i < metres.size(); ++i) {
      const double u = std::round(static_cast<double>(metres[i]) * units_per_metre);
      units[i] = u >= 1.0 && u <= 65535.0 ? static_cast<std::uint16_t>(u) : 0;
    }
    image.step = image.width * 2;
    image.data.resize(units.size() * 2);
    std::memcpy(image.data.data(), units.data(), image.data.size());
  } else {
    image.encoding = "32FC1";
    image.step = image.width * 4;
    image.data.resize(metres.size() * 4);
    std::memcpy(image.data.data(), metres.data(), image.data.size());
  }
  bag_.write(topic, received > 0.0 ? ros::Time(received) : image.header.stamp, image);
}

void BagWriter::camera_info(const std::string& topic, double stamp, const std::string& frame_id,
                            const sim::CameraSpec& camera) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = ros::Time(stamp);
  info.header.frame_id = frame_id;
  info.width = static_cast<std::uint32_t>(camera.width);
  info.height = static_cast<std::uint32_t>(camera.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  bag_.write(topic, info.header.stamp, info);
}

geometry_msgs::TransformStamped transform_message(double stamp, const std::string& parent,
                                                  const std::string& child, const Eigen::Isometry3d& parent_T_child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(stamp);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  const Eigen::Vector3d p = parent_T_child.translation();
  const Eigen::Quaterniond q(parent_T_child.linear());
  t.transform.translation.x = p.x(), t.transform.translation.y = p.y(), t.transform.translation.z = p.z();
  t.transform.rotation.x = q.x(), t.transform.rotation.y = q.y(), t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

void BagWriter::transform(const std::string& topic, double stamp, const std::string& parent,
                          const std::string& child, const Eigen::Isometry3d& parent_T_child) {
  bag_.write(topic, ros::Time(stamp), transform_message(stamp, parent, child, parent_T_child));
}

void BagWriter::tf(const std::string& topic, double stamp, const std::vector<Link>& links) {
  tf2_msgs::TFMessage message;
  for (const Link& l : links) message.transforms.push_back(transform_message(stamp, l.parent, l.child, l.parent_T_child));
  bag_.write(topic, ros::Time(stamp), message);
}

void BagWriter::point_cloud(const std::string& topic, double stamp, const std::string& frame_id,
                            const sim::CameraSpec& camera, const std::vector<float>& metres, bool organised) {
  std::vector<float> xyz;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float z = metres[static_cast<std::size_t>(v) * camera.width + u];
      const bool valid = z > 0.0f && std::isfinite(z);
      if (!valid && !organised) continue;
      const float x = static_cast<float>((u - camera.cx) * z / camera.fx);
      const float y = static_cast<float>((v - camera.cy) * z / camera.fy);
      xyz.insert(xyz.end(), {valid ? x : NAN, valid ? y : NAN, valid ? z : NAN});
    }
  }
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = ros::Time(stamp);
  cloud.header.frame_id = frame_id;
  cloud.height = organised ? static_cast<std::uint32_t>(camera.height) : 1;
  cloud.width = static_cast<std::uint32_t>(organised ? camera.width : xyz.size() / 3);
  for (const char* name : {"x", "y", "z"}) {
    sensor_msgs::PointField field;
    field.name = name;
    field.offset = static_cast<std::uint32_t>(4 * cloud.fields.size());
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.is_bigendian = false;
  cloud.point_step = 12;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = !organised;
  cloud.data.resize(xyz.size() * 4);
  std::memcpy(cloud.data.data(), xyz.data(), cloud.data.size());
  bag_.write(topic, cloud.header.stamp, cloud);
}

std::unique_ptr<RosbagWriter> open_writer(const fs::path& file, BagCompression compression) {
  return std::make_unique<BagWriter>(file, compression);
}

const RosbagFunctions kFunctions{open_reader, list_topics, open_writer};

}  // namespace
}  // namespace sonomap::harness

extern "C" const sonomap::harness::RosbagFunctions* sonomap_rosbag_functions() {
  return &sonomap::harness::kFunctions;
}
