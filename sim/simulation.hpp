// SPDX-License-Identifier: GPL-3.0-or-later
// The synthetic RGB-D sensor as one object: a scenario in, depth frames out.
// World (Embree) + DepthCamera (pinhole z-depth) + noise (seeded stages) + localisation model.
#pragma once

#include "core/types.hpp"
#include "sim/scenario.hpp"

#include <Eigen/Geometry>
#include <memory>

namespace sonomap::sim {

class World;
class DepthCamera;
class LocalisationModel;
struct DepthImage;

class Simulation {
 public:
  // Validates the scenario (meshes, camera, trajectories, noise, localisation) and builds the
  // ray-tracing world. Throws std::invalid_argument on bad input, naming what is wrong.
  explicit Simulation(const Scenario& scenario);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  int frame_count() const;          // scenario.frames
  double time_of(int frame) const;  // frame / rate_hz (fixed time step)

  // Depth, points and poses of one frame. The result depends only on (scenario, frame): the
  // same whether frames are rendered in order or not, and with any number of threads.
  // Throws std::out_of_range for frame < 0.
  Frame render(int frame);

  Eigen::Isometry3d true_body_pose(double t) const;
  Eigen::Isometry3d true_camera_pose(double t) const;
  const Scenario& scenario() const;

 private:
  Scenario scenario_;
  std::unique_ptr<World> world_;
  std::unique_ptr<DepthCamera> camera_;
  std::unique_ptr<LocalisationModel> localisation_;
  // The exact and the measured image, kept so that frames reuse their buffers.
  std::unique_ptr<DepthImage> truth_, measured_;
};

// Throws std::invalid_argument for zero / negative / non-finite intrinsics or resolution,
// min_range < 0, max_range <= min_range, rate_hz <= 0, or a non-rigid mounting.
void validate(const CameraSpec& camera);
void validate(const NoiseSpec& noise);
void validate(const LocalisationSpec& localisation);
// All of the above plus every mesh, trajectory and the frame count.
void validate(const Scenario& scenario);

}  // namespace sonomap::sim
