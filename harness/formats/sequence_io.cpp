// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/sequence_io.hpp"

#include "core/ground_plane.hpp"
#include "harness/formats/mesh_io.hpp"
#include "harness/formats/rosbag_io.hpp"
#include "harness/formats/tum_io.hpp"
#include "harness/support/errors.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <fstream>
#include <sstream>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

// Median depths outside this range mean the depth scale is wrong (e.g. millimetres read as
// metres), not that the camera saw something: no RGB-D camera works there.
constexpr double kPlausibleMedianMin = 0.05, kPlausibleMedianMax = 50.0;

class TumReader final : public RecordReader {
 public:
  TumReader(const fs::path& dir, double tolerance) : sequence_(read_tum_sequence(dir, tolerance)) {}
  int count() const override { return static_cast<int>(sequence_.frames.size()); }
  DepthRecord read(int i) override { return read_tum_record(sequence_, static_cast<std::size_t>(i)); }
  const sim::CameraSpec& camera() const override { return sequence_.camera.camera; }
  std::string name() const override { return sequence_.camera.name; }

 private:
  TumSequence sequence_;
};

// The numbers of a text file, with the line each came from.
struct Numbers {
  std::vector<double> values;
  std::vector<int> lines;
};

Numbers read_numbers(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), 0, "", "cannot read the file");
  Numbers numbers;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line);
    for (std::string w; words >> w;) {
      char* end = nullptr;
      const double v = std::strtod(w.c_str(), &end);
      if (end != w.c_str() + w.size() || !std::isfinite(v))
        throw InputError(file.string(), number, "", "'" + w + "' is not a finite number");
      numbers.values.push_back(v);
      numbers.lines.push_back(number);
    }
  }
  return numbers;
}

// Rows of a rigid camera-to-world transform (12 numbers: the top three rows) from `at` on.
Eigen::Isometry3d rigid_from_rows(const fs::path& file, const Numbers& numbers, std::size_t at) {
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r(row, col) = numbers.values[at + 4 * row + col];
    t[row] = numbers.values[at + 4 * row + 3];
  }
  const double off = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  if (off > 1e-3 || r.determinant() < 0.0)
    throw InputError(file.string(), numbers.lines[at], "",
                     "not a rigid camera-to-world transform (rotation off orthonormal by " +
                         std::to_string(off) + ")");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

// 16-bit depth PNGs and poses, frame i = pattern number first + i, time = i / rate.
class FolderReader final : public RecordReader {
 public:
  explicit FolderReader(const SequenceSpec& spec) : spec_(spec) {
    check_all_present();
    if (spec.pose_format == PoseFormat::Kitti) read_kitti(spec.path / spec.pose_file);
    for (int i = 0; spec.pose_format == PoseFormat::Matrix4x4 && i < spec.count; ++i)
      poses_.push_back(read_matrix4x4(file_of(spec.pose_pattern, i)));
  }
  int count() const override { return spec_.count; }
  const sim::CameraSpec& camera() const override { return spec_.camera; }
  DepthRecord read(int i) override {
    const fs::path file = file_of(spec_.depth_pattern, i);
    const DepthImage16 image = read_png16(file);
    if (image.width != spec_.camera.width || image.height != spec_.camera.height)
      throw InputError(file.string(), 0, "", "the image is " + std::to_string(image.width) + "x" +
                       std::to_string(image.height) + " but " + spec_.file.string() + " says " +
                       std::to_string(spec_.camera.width) + "x" + std::to_string(spec_.camera.height));
    DepthRecord record;
    record.time = i / spec_.camera.rate_hz;
    record.width = image.width;
    record.height = image.height;
    record.depth = depth_from_units(image.pixels, spec_.depth_scale);
    record.world_T_camera = poses_[static_cast<std::size_t>(i)];
    return record;
  }

 private:
  fs::path file_of(const std::string& pattern, int i) const {
    return spec_.path / expand_frame_pattern(pattern, static_cast<long long>(spec_.first) + i);
  }
  void check_all_present() const {
    std::vector<std::string> missing;
    std::error_code ec;
    for (int i = 0; i < spec_.count; ++i)
      for (const std::string* pattern : {&spec_.depth_pattern, &spec_.pose_pattern})
        if (!pattern->empty() && !fs::is_regular_file(file_of(*pattern, i), ec))
          missing.push_back(file_of(*pattern, i).filename().string());
    if (spec_.pose_format == PoseFormat::Kitti && !fs::is_regular_file(spec_.path / spec_.pose_file, ec))
      missing.push_back(spec_.pose_file.string());
    if (missing.empty()) return;
    std::string list;
    for (std::size_t k = 0; k < missing.size() && k < 20; ++k) list += "\n  " + missing[k];
    if (missing.size() > 20) list += "\n  ... and " + std::to_string(missing.size() - 20) + " more";
    throw InputError(spec_.file.string(), 0, "sequence.path",
                     std::to_string(missing.size()) + " files missing in " + spec_.path.string() + ":" + list);
  }
  static Eigen::Isometry3d read_matrix4x4(const fs::path& file) {
    const Numbers numbers = read_numbers(file);
    if (numbers.values.size() != 16)
      throw InputError(file.string(), 0, "", "expected a 4x4 matrix (16 numbers), found " +
                       std::to_string(numbers.values.size()));
    const double* last = &numbers.values[12];
    if (std::abs(last[0]) + std::abs(last[1]) + std::abs(last[2]) + std::abs(last[3] - 1.0) > 1e-6)
      throw InputError(file.string(), numbers.lines[12], "", "the last row must be 0 0 0 1");
    return rigid_from_rows(file, numbers, 0);
  }
  void read_kitti(const fs::path& file) {
    const Numbers numbers = read_numbers(file);
    if (numbers.values.size() < 12 * static_cast<std::size_t>(spec_.first + spec_.count) ||
        numbers.values.size() % 12 != 0)
      throw InputError(file.string(), 0, "", "expected 12 numbers per line (3x4 rows) for frames up to " +
                       std::to_string(spec_.first + spec_.count - 1));
    for (int i = 0; i < spec_.count; ++i)
      poses_.push_back(rigid_from_rows(file, numbers, 12 * static_cast<std::size_t>(spec_.first + i)));
  }

  const SequenceSpec spec_;
  std::vector<Eigen::Isometry3d> poses_;
};

// The rotation that takes the recording's up axis to +z (exact: entries 0 and +-1).
Eigen::Isometry3d up_to_z(const Eigen::Vector3d& up) {
  Eigen::Matrix3d r = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  r = r.array().round().matrix();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  return t;
}

std::unique_ptr<RecordReader> make_reader(const SequenceSpec& spec) {
  switch (spec.source) {
    case SequenceSource::Tum: return std::make_unique<TumReader>(spec.path, spec.time_tolerance);
    case SequenceSource::Folder: return std::make_unique<FolderReader>(spec);
    case SequenceSource::Ros1Bag: return open_rosbag_reader(spec);
  }
  return nullptr;
}

}  // namespace

RecordedSequence::RecordedSequence(SequenceSpec spec, std::unique_ptr<RecordReader> reader)
    : spec_(std::move(spec)), reader_(std::move(reader)), up_T_world_(up_to_z(spec_.up)) {
  name_ = !spec_.name.empty() ? spec_.name : !reader_->name().empty() ? reader_->name()
                                                                      : spec_.path.filename().string();
  if (reader_->count() < 1) throw InputError(spec_.file.string(), 0, "", "the recording has no frame");
  const DepthRecord first = reader_->read(0);
  time_zero_ = first.time;
  depth_images_ = !first.depth.empty();
  const double median = median_depth(first);
  if (median < kPlausibleMedianMin || median > kPlausibleMedianMax)
    throw InputError(spec_.file.string(), 0, "sequence.depth.scale",
                     "frame 0: median depth " + std::to_string(median) +
                         " m is not plausible for an RGB-D camera; check depth.scale (units per "
                         "metre: millimetres 1000, TUM 5000) and depth.encoding");
  ground_z_ = spec_.floor.value_or(0.0);
  if (spec_.auto_floor) detect_floor(first);
  if (spec_.listener_height)
    ground_z_ = aligned(0, first).world_T_body.translation().z() - *spec_.listener_height;
  load_truth();
}

namespace {

// The floor plane among the first frames' points (in the recording's world), found in a frame
// turned so that the guessed up is z, then again among the points at or below the plane found,
// turned by its normal, until no more than 1 % of the points lie 5 cm below it: a first pass may
// pick a table top or the top of a box, or lean on the walls' feet when the guess is tilted.
Eigen::Vector3d floor_normal(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d up, double& offset) {
  GroundPlaneConfig config;
  std::vector<Eigen::Vector3d> candidates = points;
  for (int pass = 0; pass < 8; ++pass) {
    const Eigen::Quaterniond to_z = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ());
    std::vector<Eigen::Vector3f> turned;
    turned.reserve(candidates.size());
    for (const Eigen::Vector3d& p : candidates) turned.push_back((to_z * p).cast<float>());
    const GroundPlane plane = estimate_ground_plane(turned, config);
    const bool moved = pass == 0 || std::abs(plane.offset - offset) > 0.01;  // the floor went down
    up = to_z.inverse() * plane.normal;
    offset = plane.offset;
    std::size_t below = 0;
    candidates.clear();
    for (const Eigen::Vector3d& p : points) {
      const double height = up.dot(p) + offset;
      below += height < -0.05;
      if (height < 0.05) candidates.push_back(p);
    }
    if (!moved && below <= points.size() / 100) break;
    config.max_tilt_deg = 10.0;  // from the second pass on, the guess is close
  }
  return up;
}

}  // namespace

// Sets the up axis and the floor from the floor plane of the first floor_frames frames; the
// first guess is the given up axis, or the first camera's up (optical -y).
void RecordedSequence::detect_floor(const DepthRecord& first) {
  const Eigen::Vector3d guess =
      spec_.up_given ? spec_.up : -(first.world_T_camera * spec_.pose_T_camera).linear().col(1);
  const int frames = std::min(reader_->count(), spec_.floor_frames);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < frames; ++i) {
    DepthRecord record = i == 0 ? first : reader_->read(i);
    record.world_T_camera = record.world_T_camera * spec_.pose_T_camera;
    const Frame frame = frame_from_record(i, record, 0.0, reader_->camera());
    const std::size_t stride = 1 + frame.points_camera.size() / 20000;  // enough for a plane
    for (std::size_t k = 0; k < frame.points_camera.size(); k += stride)
      points.push_back(frame.world_T_camera * frame.points_camera[k].cast<double>());
  }
  double offset = 0.0;
  Eigen::Vector3d normal;
  try {
    normal = floor_normal(points, guess, offset);
  } catch (const std::invalid_argument& e) {
    throw InputError(spec_.file.string(), 0, "sequence.world.floor",
                     "auto: no floor plane within 30 degrees of the guessed up axis in the first " +
                         std::to_string(frames) + " frames (" + e.what() + "); give world.up and world.floor");
  }
  up_T_world_ = Eigen::Isometry3d::Identity();
  up_T_world_.linear() = Eigen::Quaterniond::FromTwoVectors(normal, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ground_z_ = -offset;  // normal . p + offset = 0, the normal turned onto z
}

void RecordedSequence::load_truth() {
  if (spec_.truth_file.empty()) return;
  const Eigen::Isometry3d up_T_truth = up_T_world_ * spec_.world_T_truth;
  if (!spec_.truth_is_mesh) {
    truth_cloud_ = load_point_cloud(spec_.truth_file);
    for (Eigen::Vector3f& p : *truth_cloud_) p = (up_T_truth * p.cast<double>()).cast<float>();
    return;
  }
  const sim::TriangleMesh mesh = load_mesh(spec_.truth_file);
  truth_mesh_.emplace();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    sim::WorldTriangle w;
    for (int c = 0; c < 3; ++c) w[c] = up_T_truth * mesh.vertices[t[c]].cast<double>();
    truth_mesh_->push_back(w);
  }
}

Frame RecordedSequence::aligned(int i, const DepthRecord& record) const {
  DepthRecord moved = record;
  moved.world_T_camera = up_T_world_ * record.world_T_camera * spec_.pose_T_camera;
  return frame_from_record(i, moved, time_zero_, reader_->camera());
}

Frame RecordedSequence::frame(int i) { return aligned(i, reader_->read(i)); }

std::unique_ptr<RecordedSequence> open_recorded_sequence(const fs::path& input) {
  std::error_code ec;
  SequenceSpec spec;
  if (fs::is_directory(input, ec)) {
    spec.file = input;
    spec.path = input;
    spec.source = SequenceSource::Tum;
  } else {
    spec = load_sequence_spec(input);
  }
  std::unique_ptr<RecordReader> reader = make_reader(spec);
  return std::make_unique<RecordedSequence>(std::move(spec), std::move(reader));
}

}  // namespace sonomap::harness
