// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/sequence_yaml.hpp"

#include "harness/support/errors.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// One YAML map of the sequence file: typed, range-checked reads that fail naming the file, the
// line and the full key. Unknown keys are refused (a typo must not be ignored silently).
class Section {
 public:
  Section(fs::path file, YAML::Node node, std::string prefix, std::vector<std::string> known)
      : file_(std::move(file)), node_(std::move(node)), prefix_(std::move(prefix)) {
    if (!node_.IsMap()) fail(node_, "", "expected a map of keys");
    for (const auto& item : node_) {
      const std::string key = item.first.Scalar();
      bool ok = false;
      for (const auto& k : known) ok = ok || k == key;
      if (!ok) fail(item.first, key, "unknown key (known here: " + join(known) + ")");
    }
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
    const int line = at.IsDefined() && !at.Mark().is_null() ? at.Mark().line + 1 : line_of_map();
    throw InputError(file_.string(), line, full(key), what);
  }
  bool has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }
  Section section(const std::string& key, std::vector<std::string> known) const {
    if (!has(key)) fail(node_, key, "missing required section");
    return Section(file_, node_[key], full(key), std::move(known));
  }
  std::string text(const std::string& key) const {
    const YAML::Node n = node_[key];
    if (!has(key)) fail(node_, key, "missing required key");
    if (!n.IsScalar() || n.Scalar().empty()) fail(n, key, "expected a non-empty text");
    return n.Scalar();
  }
  std::string choice(const std::string& key, const std::vector<std::string>& options) const {
    const std::string value = text(key);
    for (const auto& o : options)
      if (o == value) return value;
    fail(node_[key], key, "'" + value + "' is not one of: " + join(options));
  }
  double number(const std::string& key, double lo, double hi) const {
    const YAML::Node n = node_[key];
    if (!has(key)) fail(node_, key, "missing required key");
    double v = 0.0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(n, key, "expected a number");
    if (v < lo || v > hi)
      fail(n, key, "out of range: " + n.Scalar() + " is not within [" + fmt(lo) + ", " + fmt(hi) + "]");
    return v;
  }
  double number_or(const std::string& key, double lo, double hi, double fallback) const {
    return has(key) ? number(key, lo, hi) : fallback;
  }
  int whole(const std::string& key, long long lo, long long hi) const {
    const double v = number(key, static_cast<double>(lo), static_cast<double>(hi));
    if (v != std::floor(v)) fail(node_[key], key, "expected a whole number");
    return static_cast<int>(v);
  }
  // A rigid transform: a 4x4 matrix (four rows of four numbers, last row 0 0 0 1).
  Eigen::Isometry3d transform(const std::string& key) const {
    const YAML::Node n = node_[key];
    if (!n.IsSequence() || n.size() != 4) fail(n, key, "expected a 4x4 matrix: four rows of four numbers");
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      if (!n[r].IsSequence() || n[r].size() != 4) fail(n[r], key, "row " + std::to_string(r + 1) + ": expected four numbers");
      for (int c = 0; c < 4; ++c) {
        double v = 0.0;
        if (!YAML::convert<double>::decode(n[r][c], v) || !std::isfinite(v) || std::abs(v) > 1e4)
          fail(n[r][c], key, "expected a number within [-1e4, 1e4]");
        m(r, c) = v;
      }
    }
    const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
    const double off = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
    if (off > 1e-3 || rotation.determinant() < 0.0 || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
      fail(n, key, "not a rigid transform (rotation not orthonormal, or last row not 0 0 0 1)");
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = Eigen::Quaterniond(rotation).normalized().toRotationMatrix();
    t.translation() = m.topRightCorner<3, 1>();
    return t;
  }

 private:
  static std::string join(const std::vector<std::string>& words) {
    std::string out;
    for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
    return out;
  }
  static std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }
  std::string full(const std::string& key) const {
    return prefix_.empty() ? key : key.empty() ? prefix_ : prefix_ + "." + key;
  }
  int line_of_map() const { return node_.Mark().is_null() ? 0 : node_.Mark().line + 1; }

  fs::path file_;
  YAML::Node node_;
  std::string prefix_;
};

Eigen::Vector3d up_axis(const Section& world) {
  const std::string up = world.choice("up", {"+x", "-x", "+y", "-y", "+z", "-z"});
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis[up[1] - 'x'] = up[0] == '+' ? 1.0 : -1.0;
  return axis;
}

void read_depth(const Section& top, SequenceSpec& spec) {
  const Section depth = top.section("depth", {"pattern", "topic", "encoding", "scale"});
  if (spec.source == SequenceSource::Folder) spec.depth_pattern = depth.text("pattern");
  if (spec.source == SequenceSource::Ros1Bag) spec.depth_topic = depth.text("topic");
  const std::string encoding = depth.choice("encoding", {"16UC1", "32FC1", "PointCloud2"});
  spec.encoding = encoding == "16UC1" ? DepthEncoding::Mono16
                  : encoding == "32FC1" ? DepthEncoding::Float32 : DepthEncoding::PointCloud2;
  if (spec.encoding != DepthEncoding::Mono16) {
    if (depth.has("scale")) depth.fail(YAML::Node(), "scale", encoding + " depth is in metres; remove scale");
  } else if (!depth.has("scale")) {
    depth.fail(YAML::Node(), "scale",
               "missing: say how many 16UC1 units make a metre (millimetre PNGs: 1000, TUM: 5000)");
  } else {
    spec.depth_scale = depth.number("scale", 1.0, 1e5);
  }
  if (spec.source == SequenceSource::Folder && spec.encoding != DepthEncoding::Mono16)
    depth.fail(YAML::Node(), "encoding", "folders hold 16-bit PNGs: use 16UC1");
}

void read_camera(const Section& top, SequenceSpec& spec) {
  const Section camera = top.section(
      "camera", {"width", "height", "intrinsics", "info_topic", "min_range", "max_range", "rate", "body_T_camera"});
  sim::CameraSpec& c = spec.camera;
  if (spec.source == SequenceSource::Ros1Bag && camera.has("info_topic")) {
    spec.camera_info_topic = camera.text("info_topic");
  } else {
    c.width = camera.whole("width", 1, 16384);
    c.height = camera.whole("height", 1, 16384);
    const Section k = camera.section("intrinsics", {"fx", "fy", "cx", "cy"});
    c.fx = k.number("fx", 1.0, 1e5);
    c.fy = k.number("fy", 1.0, 1e5);
    c.cx = k.number("cx", -c.width, 2.0 * c.width);
    c.cy = k.number("cy", -c.height, 2.0 * c.height);
  }
  c.min_range = camera.number_or("min_range", 0.0, 100.0, c.min_range);
  c.max_range = camera.number_or("max_range", 0.01, 1000.0, c.max_range);
  if (c.max_range <= c.min_range) camera.fail(YAML::Node(), "max_range", "must exceed min_range");
  c.rate_hz = camera.number_or("rate", 0.1, 1000.0, spec.source == SequenceSource::Folder ? 30.0 : c.rate_hz);
  if (camera.has("body_T_camera")) c.body_T_camera = camera.transform("body_T_camera");
}

void read_poses(const Section& top, SequenceSpec& spec) {
  const Section poses = top.section("poses", {"format", "pattern", "file", "topic", "pose_T_camera"});
  if (spec.source == SequenceSource::Folder) {
    const std::string format = poses.choice("format", {"matrix4x4", "kitti"});
    spec.pose_format = format == "kitti" ? PoseFormat::Kitti : PoseFormat::Matrix4x4;
    if (spec.pose_format == PoseFormat::Matrix4x4) spec.pose_pattern = poses.text("pattern");
    if (spec.pose_format == PoseFormat::Kitti) spec.pose_file = poses.text("file");
  } else {
    poses.choice("format", {"topic"});
    spec.pose_format = PoseFormat::Topic;
    spec.pose_topic = poses.text("topic");
  }
  if (poses.has("pose_T_camera")) spec.pose_T_camera = poses.transform("pose_T_camera");
}

void read_world_and_time(const Section& top, SequenceSpec& spec) {
  if (top.has("world")) {
    const Section world = top.section("world", {"up", "floor", "listener_height", "floor_frames"});
    spec.up_given = world.has("up");
    if (spec.up_given) spec.up = up_axis(world);
    if (world.has("floor") && world.has("listener_height"))
      world.fail(YAML::Node(), "floor", "give floor or listener_height, not both");
    spec.auto_floor = world.has("floor") && world.text("floor") == "auto";
    if (world.has("floor") && !spec.auto_floor) spec.floor = world.number("floor", -1e4, 1e4);
    if (world.has("floor_frames") && !spec.auto_floor)
      world.fail(YAML::Node(), "floor_frames", "only used with floor: auto");
    if (world.has("floor_frames")) spec.floor_frames = world.whole("floor_frames", 1, 1000);
    if (world.has("listener_height")) spec.listener_height = world.number("listener_height", 0.0, 10.0);
  }
  if (top.has("time")) {
    const Section time = top.section("time", {"tolerance", "match"});
    spec.time_tolerance = time.number_or("tolerance", 0.0, 10.0, spec.time_tolerance);
    if (time.has("match")) spec.interpolate = time.choice("match", {"nearest", "interpolate"}) == "interpolate";
  }
}

void read_truth(const Section& top, SequenceSpec& spec) {
  if (!top.has("truth")) return;
  const Section truth = top.section("truth", {"cloud", "mesh", "world_T_truth"});
  if (truth.has("cloud") == truth.has("mesh"))
    truth.fail(YAML::Node(), "cloud", "give the reference as cloud (points) or mesh (triangles), one of them");
  spec.truth_is_mesh = truth.has("mesh");
  spec.truth_file = truth.text(spec.truth_is_mesh ? "mesh" : "cloud");
  if (spec.truth_file.is_relative()) spec.truth_file = spec.file.parent_path() / spec.truth_file;
  if (truth.has("world_T_truth")) spec.world_T_truth = truth.transform("world_T_truth");
}

YAML::Node load(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string(), 0, "", "missing or not a regular file");
  try {
    return YAML::LoadFile(file.string());
  } catch (const YAML::ParserException& e) {
    throw InputError(file.string(), e.mark.is_null() ? 0 : e.mark.line + 1, "", "malformed YAML: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw InputError(file.string(), 0, "", "cannot read the file: " + e.msg);
  }
}

}  // namespace

bool is_sequence_file(const fs::path& file) {
  if (file.filename() == "sequence.yaml") return true;
  try {
    const YAML::Node root = YAML::LoadFile(file.string());
    return root.IsMap() && root["sequence"].IsDefined();
  } catch (const std::exception&) {
    return false;
  }
}

std::string expand_frame_pattern(const std::string& pattern, long long number) {
  const std::size_t start = pattern.find('#');
  const std::size_t end = pattern.find_first_not_of('#', start);
  const std::size_t width = (end == std::string::npos ? pattern.size() : end) - start;
  std::string digits = std::to_string(number);
  if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
  return pattern.substr(0, start) + digits + (end == std::string::npos ? "" : pattern.substr(end));
}

SequenceSpec load_sequence_spec(const fs::path& file) {
  const YAML::Node root = load(file);
  if (!root.IsMap() || !root["sequence"].IsDefined())
    throw InputError(file.string(), 0, "sequence", "expected a top-level 'sequence:' map (see docs/real-data.md)");
  const Section top(file, root["sequence"], "sequence",
                    {"name", "source", "path", "depth", "frames", "camera", "poses", "world", "time", "truth"});
  SequenceSpec spec;
  spec.file = file;
  const std::string source = top.choice("source", {"tum", "folder", "ros1_bag"});
  spec.source = source == "tum" ? SequenceSource::Tum
                : source == "folder" ? SequenceSource::Folder : SequenceSource::Ros1Bag;
  spec.path = top.text("path");
  if (spec.path.is_relative()) spec.path = file.parent_path() / spec.path;
  if (top.has("name")) spec.name = top.text("name");
  if (spec.source != SequenceSource::Tum) {
    read_depth(top, spec);
    read_camera(top, spec);
    read_poses(top, spec);
  } else {
    for (const char* key : {"depth", "camera", "poses", "frames"})
      if (top.has(key)) top.fail(YAML::Node(), key, "a TUM folder says this in its own camera.yaml and text files");
  }
  if (spec.source == SequenceSource::Folder) {
    const Section frames = top.section("frames", {"first", "count"});
    spec.first = frames.has("first") ? frames.whole("first", 0, 100000000) : 0;
    spec.count = frames.whole("count", 1, 10000000);
    for (const std::string& p : {spec.depth_pattern, spec.pose_pattern})
      if (!p.empty() && p.find('#') == std::string::npos)
        top.fail(YAML::Node(), p == spec.depth_pattern ? "depth.pattern" : "poses.pattern",
                 "'" + p + "' has no '#' run for the frame number");
  } else if (top.has("frames")) {
    top.fail(YAML::Node(), "frames", "only a folder source lists its frames (use run --frames)");
  }
  read_world_and_time(top, spec);
  read_truth(top, spec);
  return spec;
}

}  // namespace sonomap::harness
