// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/localisation.hpp"

#include "sim/random.hpp"
#include "sim/trajectory.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::sim {

namespace {

void require_non_negative(double value, const char* name) {
  if (!(std::isfinite(value) && value >= 0.0))
    throw std::invalid_argument(std::string("localisation: ") + name +
                                " must be finite and >= 0, got " + std::to_string(value));
}

}  // namespace

LocalisationModel::LocalisationModel(const LocalisationSpec& spec, std::uint64_t seed,
                                     std::uint64_t sensor, double frame_period)
    : spec_(spec), seed_(seed), sensor_(sensor), frame_period_(frame_period) {
  require_non_negative(spec.translation_noise, "translation_noise");
  require_non_negative(spec.yaw_noise, "yaw_noise");
  require_non_negative(spec.translation_drift, "translation_drift");
  require_non_negative(spec.yaw_drift, "yaw_drift");
  if (!std::isfinite(spec.time_offset))
    throw std::invalid_argument("localisation: time_offset must be finite");
  if (!(std::isfinite(frame_period) && frame_period > 0.0))
    throw std::invalid_argument("localisation: frame period must be positive");
}

bool LocalisationModel::is_exact() const {
  return spec_.translation_noise == 0.0 && spec_.yaw_noise == 0.0 && spec_.translation_drift == 0.0 &&
         spec_.yaw_drift == 0.0;
}

LocalisationModel::Drift LocalisationModel::drift_at(int frame) {
  if (spec_.translation_drift == 0.0 && spec_.yaw_drift == 0.0) return Drift{};
  if (frame < cached_frame_) {
    cached_frame_ = 0;
    cached_drift_ = Drift{};
  }
  const double step = std::sqrt(frame_period_);
  for (int k = cached_frame_ + 1; k <= frame; ++k) {
    RandomStream rng({seed_, sensor_, static_cast<std::uint64_t>(k),
                      static_cast<std::uint64_t>(StreamPurpose::LocalisationDrift)});
    for (int axis = 0; axis < 3; ++axis)
      cached_drift_.translation[axis] += rng.normal(spec_.translation_drift * step);
    cached_drift_.yaw += rng.normal(spec_.yaw_drift * step);
  }
  cached_frame_ = frame;
  return cached_drift_;
}

Eigen::Isometry3d LocalisationModel::estimated_body_pose(const TrajectorySpec& body, int frame, double t) {
  Eigen::Isometry3d pose = pose_at(body, t + spec_.time_offset);
  if (is_exact()) return pose;
  const Drift drift = drift_at(frame);
  RandomStream rng({seed_, sensor_, static_cast<std::uint64_t>(frame),
                    static_cast<std::uint64_t>(StreamPurpose::LocalisationNoise)});
  Eigen::Vector3d noise;
  for (int axis = 0; axis < 3; ++axis) noise[axis] = rng.normal(spec_.translation_noise);
  const double yaw = drift.yaw + rng.normal(spec_.yaw_noise);
  pose.translation() += drift.translation + noise;
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * pose.linear();
  return pose;
}

}  // namespace sonomap::sim
