// SPDX-License-Identifier: GPL-3.0-or-later
// Scenario files: YAML (metres, seconds, degrees) -> sim::Scenario (radians, quaternions).
// The format is documented in scenes/README.md. Every problem is an InputError naming the file,
// the 1-based line and the dotted key (sequence items as `body.keyframes[3].time`).
#pragma once

#include "sim/scenario.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace sonomap::harness {

// Reads, overrides, validates and converts a scenario; loads mesh files (paths relative to the
// YAML file) and triangulates primitives, so every object comes back with its mesh.
// `overrides` are "dotted.key=value" strings (value parsed as YAML) applied to the document
// before validation; sequence items are addressed by index (`static.0.pose.yaw=90`) or by
// their `name` (`moving.person.appear=2`). Setting `frames` drops `duration` and vice versa.
// An error caused by an override names the override.
sim::Scenario load_scenario(const std::filesystem::path& file,
                            const std::vector<std::string>& overrides = {});

// A sequence's camera.yaml: the camera keys of a scenario's `sensor` section (no noise), plus
// the depth PNG scale. Lets recorded sequences (TUM RGB-D layout) be read back.
struct CameraFile {
  std::string name;
  sim::CameraSpec camera;
  double depth_scale = 5000.0;  // PNG units per metre
};
CameraFile load_camera_file(const std::filesystem::path& file);
// The YAML text load_camera_file reads back exactly (numbers with 17 significant digits).
std::string camera_file_text(const CameraFile& file);

// Pose from the YAML angles: world_R = Rz(yaw) * Ry(pitch) * Rx(roll), degrees. With z up, a
// positive pitch tilts the x axis down (right-hand rule about +y), as in ROS (REP 103).
Eigen::Quaterniond quaternion_from_ypr_degrees(double yaw, double pitch, double roll);

}  // namespace sonomap::harness
