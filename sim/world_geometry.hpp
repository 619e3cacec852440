// SPDX-License-Identifier: GPL-3.0-or-later
// The scene's true geometry at time t as plain world-frame triangles (no Embree): what the
// ground-truth rasters are computed from.
#pragma once

#include "sim/scenario.hpp"

#include <Eigen/Core>
#include <array>
#include <vector>

namespace sonomap::sim {

using WorldTriangle = std::array<Eigen::Vector3d, 3>;

// A moving object is present at t when appear_time <= t < disappear_time.
bool is_present(const MovingObject& mover, double t);

// Every static triangle in the world frame, plus every moving object present at t placed at
// pose_at(its trajectory, t). Objects with an empty mesh use their triangulated shape
// (mesh_of in sim/primitives.hpp), exactly as the simulator does.
std::vector<WorldTriangle> world_triangles(const Scenario& scenario, double t);

}  // namespace sonomap::sim
