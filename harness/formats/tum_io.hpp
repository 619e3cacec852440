// SPDX-License-Identifier: GPL-3.0-or-later
// Depth sequences in the TUM RGB-D layout, so other tools can read what sonomap simulates and
// sonomap can run on recorded data:
//   depth/<timestamp>.png  16-bit grey, z-depth x depth_scale (5000 per metre), 0 = no return
//   depth.txt              "timestamp filename" per frame, TUM header comments
//   groundtruth.txt        "timestamp tx ty tz qx qy qz qw": the true camera pose in the world
//   camera.yaml            intrinsics, size, ranges, rate, depth scale, camera on the body
#pragma once

#include "core/types.hpp"
#include "harness/formats/scenario_yaml.hpp"
#include "harness/formats/sequence_frame.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

constexpr double kTumDepthScale = 5000.0;  // PNG units per metre, as in TUM RGB-D

// 16-bit greyscale PNG. Throws InputError naming the file (missing, not a 16-bit grey PNG,
// corrupt); write throws std::runtime_error when the file cannot be written.
struct DepthImage16 {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> pixels;  // row-major
};
void write_png16(const std::filesystem::path& file, const DepthImage16& image);
DepthImage16 read_png16(const std::filesystem::path& file);

// Writes frames into an existing directory (e.g. a StagedDirectory's path): add() writes one
// PNG, finish() writes the three text files.
class TumWriter {
 public:
  TumWriter(std::filesystem::path dir, CameraFile camera);
  // Depth in metres to PNG units (rounded); a depth the 16 bits cannot hold becomes 0. The
  // true camera pose goes to groundtruth.txt.
  void add(const Frame& frame, const Eigen::Isometry3d& world_T_camera_true);
  void finish();

 private:
  std::filesystem::path dir_;
  CameraFile camera_;
  std::string depth_list_;
  std::string groundtruth_;
};

// One frame of a sequence: its depth PNG and the camera pose associated with it.
struct TumFrameInfo {
  double timestamp = 0.0;
  std::filesystem::path depth_file;  // absolute (dir / the name in depth.txt)
  Eigen::Isometry3d world_T_camera = Eigen::Isometry3d::Identity();
};

struct TumSequence {
  std::filesystem::path dir;
  CameraFile camera;
  std::vector<TumFrameInfo> frames;  // in depth.txt order, those with a pose
  int frames_without_pose = 0;       // depth frames with no pose within max_time_difference
};

// Reads depth.txt, groundtruth.txt and camera.yaml. Each depth frame takes the ground-truth
// pose nearest in time, if within max_time_difference seconds (as TUM's associate.py).
// Throws InputError naming the file and line for anything malformed, and when no frame has
// a pose. Depth images are read lazily by load_tum_frame.
TumSequence read_tum_sequence(const std::filesystem::path& dir,
                              double max_time_difference = 0.02);

// Frame i's depth image in metres and its pose (the recording's clock).
DepthRecord read_tum_record(const TumSequence& sequence, std::size_t i);

// Frame i as the mapper sees it: z-depth in metres (0 outside [min_range, max_range]), the
// back-projected points, and the recorded pose as the given one (a run takes it as the true
// pose too; the body pose is camera pose * camera_T_body). time = timestamp - first frame's timestamp.
Frame load_tum_frame(const TumSequence& sequence, std::size_t i);

}  // namespace sonomap::harness
