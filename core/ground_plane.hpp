// SPDX-License-Identifier: GPL-3.0-or-later
// A robust ground-plane estimate for data without a known ground: RANSAC over the lowest
// points (the ground is what the lowest points mostly are, walls and furniture rise above it),
// then a least-squares refit on every point near the winning plane. Deterministic for a seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sonomap {

struct GroundPlaneConfig {
  double lowest_fraction = 0.5;   // RANSAC samples among this fraction of points, lowest z first
  int iterations = 200;           // RANSAC hypotheses
  double inlier_distance = 0.03;  // metres from the plane
  double max_tilt_deg = 30.0;     // steeper hypotheses (walls, ramps) are not ground
  int refits = 2;                 // least-squares refits, each re-collecting the inliers
  std::uint64_t seed = 1;
};

// The plane normal . p + offset = 0, normal of unit length pointing up (normal.z > 0).
struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  int inliers = 0;          // points within inlier_distance of the final plane
  double rms = 0.0;         // RMS distance of those inliers, metres

  // Signed distance of p above the plane.
  double height_of(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  // The plane's z under (x, y) (its height where a raster origin stands).
  double z_at(double x, double y) const {
    return -(offset + normal.x() * x + normal.y() * y) / normal.z();
  }
  double tilt_deg() const;  // angle between the normal and world z
};

// Non-finite points are skipped. Throws std::invalid_argument for an invalid config, fewer
// than 3 finite points, or when no hypothesis within max_tilt_deg has 3 inliers.
GroundPlane estimate_ground_plane(const std::vector<Eigen::Vector3f>& points,
                                  const GroundPlaneConfig& config = {});

}  // namespace sonomap
