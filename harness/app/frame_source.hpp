// SPDX-License-Identifier: GPL-3.0-or-later
// Where a run's frames come from: the simulator (with exact ground truth) or a recorded
// sequence (no ground truth). The run loop sees only FrameSource.
#pragma once

#include "core/types.hpp"
#include "eval/moved_ghosts.hpp"
#include "sim/scenario.hpp"
#include "sim/world_geometry.hpp"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sonomap::harness {

// A frame as the mapper gets it (depth, points, the ESTIMATED pose) and the true body pose,
// which stays with the evaluator.
struct SourceFrame {
  Frame frame;
  Eigen::Isometry3d world_T_body_true = Eigen::Isometry3d::Identity();
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::string name() const = 0;
  virtual int frame_count() const = 0;
  virtual SourceFrame frame(int i) = 0;
  virtual double ground_z() const = 0;
  virtual std::uint64_t seed() const = 0;
  // World triangles at time t, or nullopt when there is no ground truth (recorded data).
  virtual std::optional<std::vector<sim::WorldTriangle>> truth(double t) const = 0;
  // The moving objects (their shapes' boxes) and their true poses at time t, one per object
  // (none while it is out of the scene): what the moved-object ghosts are measured from.
  virtual std::vector<eval::MovingObjectShape> moving_objects() const { return {}; }
  virtual std::vector<std::optional<Eigen::Isometry3d>> moving_poses(double) const { return {}; }
  // A reference point cloud of a static scene (a recording's truth.cloud), or null: the truth
  // is then the minimum over its points in each cell (eval/cloud_truth.hpp).
  virtual const std::vector<Eigen::Vector3f>* truth_cloud() const { return nullptr; }
  // Where a recording's truth comes from (summary.json ground_truth_note); empty: the default.
  virtual std::string truth_note() const { return {}; }
  // False when the frames carry points but no depth image (an unorganised point cloud).
  virtual bool depth_images() const { return true; }
  // The files and folders it reads (no output may be, contain or lie inside one).
  virtual std::vector<std::filesystem::path> inputs() const = 0;
  // The listener's head when the scenario moves it apart from the body (rendering only).
  virtual std::optional<sim::HeadSpec> head() const { return std::nullopt; }
};

// A scenario's files: the YAML itself and the meshes it names.
std::vector<std::filesystem::path> scenario_inputs(const sim::Scenario& scenario,
                                                   const std::filesystem::path& file);

// The frame source a run's input names: a directory (a recorded TUM RGB-D sequence) or a
// sequence file (sequence.yaml, or a top-level `sequence:` key) is a recording (its first
// `frames` frames; 0: all), anything else a scenario YAML file loaded with `overrides`
// (its frame count set by `frames` > 0 and its seed by `seed`).
std::unique_ptr<FrameSource> open_frame_source(const std::filesystem::path& input,
                                               std::vector<std::string> overrides, int frames,
                                               std::optional<std::uint64_t> seed);

}  // namespace sonomap::harness
