// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/simulation.hpp"

#include "sim/depth_camera.hpp"
#include "sim/localisation.hpp"
#include "sim/noise.hpp"
#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"
#include "sim/world.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

// One simulated sensor per scenario; its id keys the random streams.
constexpr std::uint64_t kSensorId = 0;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

void validate(const CameraSpec& c) {
  require(c.width > 0 && c.height > 0, "camera: resolution must be positive, got " +
                                           std::to_string(c.width) + "x" + std::to_string(c.height));
  require(positive(c.fx), "camera: fx must be positive and finite, got " + std::to_string(c.fx));
  require(positive(c.fy), "camera: fy must be positive and finite, got " + std::to_string(c.fy));
  require(std::isfinite(c.cx) && std::isfinite(c.cy), "camera: cx and cy must be finite");
  require(std::isfinite(c.min_range) && c.min_range >= 0.0,
          "camera: min_range must be finite and >= 0, got " + std::to_string(c.min_range));
  require(std::isfinite(c.max_range) && c.max_range > c.min_range,
          "camera: max_range (" + std::to_string(c.max_range) + ") must be finite and greater than min_range (" +
              std::to_string(c.min_range) + ")");
  require(positive(c.rate_hz), "camera: rate_hz must be positive, got " + std::to_string(c.rate_hz));
  const Eigen::Matrix3d r = c.body_T_camera.linear();
  require(c.body_T_camera.matrix().allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
              r.determinant() > 0.0,
          "camera: body_T_camera must be a rigid transform (rotation plus translation)");
}

void validate(const NoiseSpec& n) {
  require(std::isfinite(n.dropout) && n.dropout >= 0.0 && n.dropout <= 1.0,
          "noise: dropout must be in [0, 1], got " + std::to_string(n.dropout));
  require(positive(n.baseline), "noise: baseline must be positive, got " + std::to_string(n.baseline));
  require(positive(n.disparity_step),
          "noise: disparity_step must be positive, got " + std::to_string(n.disparity_step));
  require(positive(n.edge_threshold),
          "noise: edge_threshold must be positive, got " + std::to_string(n.edge_threshold));
  require(positive(n.grazing_angle) && n.grazing_angle <= M_PI / 2,
          "noise: grazing_angle must be in (0, 90] degrees, got " + std::to_string(n.grazing_angle) + " rad");
}

void validate(const LocalisationSpec& l) { LocalisationModel(l, 0, 0, 1.0); }

void validate(const Scenario& s) {
  validate(s.camera);
  validate(s.noise);
  validate(s.localisation);
  require(s.frames >= 1, "scenario: frames must be at least 1, got " + std::to_string(s.frames));
  require(std::isfinite(s.ground_z), "scenario: ground_z must be finite");
  auto context = [](const std::string& what, const std::string& name, const std::exception& e) {
    return what + " '" + name + "': " + e.what();
  };
  for (const StaticObject& object : s.statics) {
    try {
      require(object.pose.matrix().allFinite(), "pose is not finite");
      validate(mesh_of(object.shape, object.mesh));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(context("static object", object.name, e));
    }
  }
  for (const MovingObject& mover : s.movers) {
    try {
      validate(mesh_of(mover.shape, mover.mesh));
      validate(mover.trajectory);
      require(!std::isnan(mover.appear_time) && !std::isnan(mover.disappear_time) &&
                  mover.appear_time <= mover.disappear_time,
              "appear_time must not be after disappear_time");
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(context("moving object", mover.name, e));
    }
  }
  try {
    validate(s.body);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("body ") + e.what());
  }
}

Simulation::Simulation(const Scenario& scenario) : scenario_(scenario) {
  validate(scenario_);
  // Triangulate primitives once, so the World and anyone reading scenario() see the same meshes.
  for (StaticObject& object : scenario_.statics) object.mesh = mesh_of(object.shape, object.mesh);
  for (MovingObject& mover : scenario_.movers) mover.mesh = mesh_of(mover.shape, mover.mesh);
  world_ = std::make_unique<World>(scenario_);
  camera_ = std::make_unique<DepthCamera>(scenario_.camera);
  localisation_ = std::make_unique<LocalisationModel>(scenario_.localisation, scenario_.seed, kSensorId,
                                                      1.0 / scenario_.camera.rate_hz);
  truth_ = std::make_unique<DepthImage>();
  measured_ = std::make_unique<DepthImage>();
}

Simulation::~Simulation() = default;

int Simulation::frame_count() const { return scenario_.frames; }

double Simulation::time_of(int frame) const { return frame / scenario_.camera.rate_hz; }

Eigen::Isometry3d Simulation::true_body_pose(double t) const { return pose_at(scenario_.body, t); }

Eigen::Isometry3d Simulation::true_camera_pose(double t) const {
  return true_body_pose(t) * scenario_.camera.body_T_camera;
}

const Scenario& Simulation::scenario() const { return scenario_; }

Frame Simulation::render(int frame) {
  if (frame < 0) throw std::out_of_range("Simulation::render: negative frame index " + std::to_string(frame));
  const double t = time_of(frame);
  Frame out;
  out.index = frame;
  out.time = t;
  out.width = scenario_.camera.width;
  out.height = scenario_.camera.height;
  const CameraSpec& c = scenario_.camera;
  out.intrinsics = PinholeIntrinsics{c.fx, c.fy, c.cx, c.cy};
  out.world_T_body = localisation_->estimated_body_pose(scenario_.body, frame, t);
  out.world_T_camera = out.world_T_body * scenario_.camera.body_T_camera;

  world_->set_time(t);
  camera_->trace(*world_, true_camera_pose(t), *truth_);
  const NoiseKey key{scenario_.seed, kSensorId, static_cast<std::uint64_t>(frame)};
  apply_noise(*truth_, scenario_.noise, scenario_.camera.fx, key, *measured_);
  *measured_ = camera_->clip_to_range(std::move(*measured_));
  out.depth = measured_->z;  // a copy: the buffer stays for the next frame
  out.points_camera = camera_->back_project(out.depth);
  return out;
}

}  // namespace sonomap::sim
