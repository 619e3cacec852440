// SPDX-License-Identifier: GPL-3.0-or-later
// A recording as the run sees it: frames in a z-up world with a known floor, whatever the
// recording's format (a TUM folder, a folder of depth PNGs and pose files, a ROS1 bag).
#pragma once

#include "core/types.hpp"
#include "harness/formats/sequence_frame.hpp"
#include "harness/formats/sequence_yaml.hpp"
#include "sim/world_geometry.hpp"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace sonomap::harness {

// One recording format: its frames in the recording's own world, in order.
class RecordReader {
 public:
  virtual ~RecordReader() = default;
  virtual int count() const = 0;
  virtual DepthRecord read(int i) = 0;  // called with i = 0, 1, 2, ... (bags stream)
  virtual const sim::CameraSpec& camera() const = 0;
  virtual std::string name() const { return {}; }  // the recording's own name, if it has one
};

class RecordedSequence {
 public:
  // Reads frame 0 to place the floor and to check the depth scale is plausible.
  RecordedSequence(SequenceSpec spec, std::unique_ptr<RecordReader> reader);
  const std::string& name() const { return name_; }
  int frame_count() const { return reader_->count(); }
  // Frame i with z up (the recording's world rotated about its origin) and the floor at
  // ground_z(); world_T_camera = aligned recorded pose * pose_T_camera.
  Frame frame(int i);
  double ground_z() const { return ground_z_; }
  bool depth_images() const { return depth_images_; }  // frame 0 had an image (not bare points)
  // The sequence file's reference (truth.cloud or truth.mesh) in the z-up world; null without.
  const std::vector<Eigen::Vector3f>* truth_cloud() const { return truth_cloud_ ? &*truth_cloud_ : nullptr; }
  const std::vector<sim::WorldTriangle>* truth_mesh() const { return truth_mesh_ ? &*truth_mesh_ : nullptr; }

 private:
  void load_truth();
  void detect_floor(const DepthRecord& first);
  Frame aligned(int i, const DepthRecord& record) const;
  SequenceSpec spec_;
  std::unique_ptr<RecordReader> reader_;
  std::string name_;
  Eigen::Isometry3d up_T_world_ = Eigen::Isometry3d::Identity();
  double time_zero_ = 0.0;
  double ground_z_ = 0.0;
  bool depth_images_ = true;
  std::optional<std::vector<Eigen::Vector3f>> truth_cloud_;
  std::optional<std::vector<sim::WorldTriangle>> truth_mesh_;
};

// A TUM RGB-D folder (z up, floor at z = 0) or a sequence file. Throws InputError naming the
// file and line, or the frame (every missing file of a folder at once).
std::unique_ptr<RecordedSequence> open_recorded_sequence(const std::filesystem::path& input);

}  // namespace sonomap::harness
