// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/world_geometry.hpp"

#include "sim/primitives.hpp"
#include "sim/trajectory.hpp"

namespace sonomap::sim {

namespace {

void append_transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& world_T_object,
                        std::vector<WorldTriangle>& out) {
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    WorldTriangle w;
    for (int c = 0; c < 3; ++c) w[c] = world_T_object * mesh.vertices[tri[c]].cast<double>();
    out.push_back(w);
  }
}

}  // namespace

bool is_present(const MovingObject& mover, double t) {
  return mover.appear_time <= t && t < mover.disappear_time;
}

std::vector<WorldTriangle> world_triangles(const Scenario& scenario, double t) {
  std::vector<WorldTriangle> out;
  for (const StaticObject& object : scenario.statics)
    append_transformed(mesh_of(object.shape, object.mesh), object.pose, out);
  for (const MovingObject& mover : scenario.movers)
    if (is_present(mover, t))
      append_transformed(mesh_of(mover.shape, mover.mesh), pose_at(mover.trajectory, t), out);
  return out;
}

}  // namespace sonomap::sim
