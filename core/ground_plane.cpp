// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/ground_plane.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace sonomap {

namespace {

constexpr double kDeg = M_PI / 180.0;

void validate(const GroundPlaneConfig& c) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("ground plane config: " + what);
  };
  if (!(c.lowest_fraction > 0.0 && c.lowest_fraction <= 1.0)) fail("lowest_fraction must be in (0, 1]");
  if (c.iterations < 1) fail("iterations must be >= 1");
  if (!(c.inlier_distance > 0.0) || !std::isfinite(c.inlier_distance)) fail("inlier_distance must be > 0");
  if (!(c.max_tilt_deg >= 0.0 && c.max_tilt_deg < 90.0)) fail("max_tilt_deg must be in [0, 90)");
  if (c.refits < 0) fail("refits must be >= 0");
}

// Plane with an upward unit normal; false if degenerate or too steep.
bool plane_through(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   double min_normal_z, GroundPlane& out) {
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double norm = n.norm();
  if (!(norm > 1e-12)) return false;
  n /= norm;
  if (n.z() < 0.0) n = -n;
  if (n.z() < min_normal_z) return false;
  out.normal = n;
  out.offset = -n.dot(a);
  return true;
}

int count_inliers(const std::vector<Eigen::Vector3d>& points, size_t count,
                  const GroundPlane& plane, double distance) {
  int inliers = 0;
  for (size_t i = 0; i < count; ++i) {
    if (std::abs(plane.height_of(points[i])) <= distance) ++inliers;
  }
  return inliers;
}

// Total least squares: the plane through the inliers' centroid normal to their direction of
// least spread. Returns false when fewer than 3 inliers support it.
bool refit(const std::vector<Eigen::Vector3d>& points, double distance, GroundPlane& plane) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& p : points) {
    if (std::abs(plane.height_of(p)) <= distance) {
      sum += p;
      ++n;
    }
  }
  if (n < 3) return false;
  const Eigen::Vector3d centroid = sum / n;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    if (std::abs(plane.height_of(p)) <= distance) {
      const Eigen::Vector3d d = p - centroid;
      scatter += d * d.transpose();
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);  // smallest eigenvalue first
  if (normal.z() < 0.0) normal = -normal;
  plane.normal = normal.normalized();
  plane.offset = -plane.normal.dot(centroid);
  return true;
}

}  // namespace

double GroundPlane::tilt_deg() const {
  return std::acos(std::clamp(normal.z() / normal.norm(), -1.0, 1.0)) / kDeg;
}

GroundPlane estimate_ground_plane(const std::vector<Eigen::Vector3f>& input,
                                  const GroundPlaneConfig& config) {
  validate(config);
  std::vector<Eigen::Vector3d> points;
  points.reserve(input.size());
  for (const auto& p : input) {
    if (p.allFinite()) points.push_back(p.cast<double>());
  }
  if (points.size() < 3) {
    throw std::invalid_argument("ground plane: need at least 3 finite points, got " +
                                std::to_string(points.size()));
  }

  // The lowest points first; RANSAC draws from those only.
  std::vector<Eigen::Vector3d> lowest = points;
  const size_t count = std::max<size_t>(
      3, static_cast<size_t>(std::ceil(config.lowest_fraction * static_cast<double>(points.size()))));
  const auto by_z = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); };
  std::nth_element(lowest.begin(), lowest.begin() + static_cast<long>(count - 1), lowest.end(), by_z);

  std::mt19937_64 rng(config.seed);
  const double min_normal_z = std::cos(config.max_tilt_deg * kDeg);
  GroundPlane best;
  int best_inliers = 0;
  for (int it = 0; it < config.iterations; ++it) {
    // Three distinct indices; modulo bias is negligible for point counts << 2^64.
    const size_t i = rng() % count;
    const size_t j = rng() % count;
    const size_t k = rng() % count;
    if (i == j || j == k || i == k) continue;
    GroundPlane hypothesis;
    if (!plane_through(lowest[i], lowest[j], lowest[k], min_normal_z, hypothesis)) continue;
    const int inliers = count_inliers(lowest, count, hypothesis, config.inlier_distance);
    if (inliers > best_inliers) {  // strict: the first best hypothesis wins ties
      best_inliers = inliers;
      best = hypothesis;
    }
  }
  if (best_inliers < 3) {
    throw std::invalid_argument("ground plane: no plane within " +
                                std::to_string(config.max_tilt_deg) +
                                " degrees of level is supported by 3 points");
  }

  for (int r = 0; r < config.refits; ++r) {
    GroundPlane refined = best;
    if (!refit(points, config.inlier_distance, refined) || refined.normal.z() < min_normal_z) break;
    best = refined;
  }
  double sum_sq = 0.0;
  best.inliers = 0;
  for (const auto& p : points) {
    const double h = best.height_of(p);
    if (std::abs(h) <= config.inlier_distance) {
      ++best.inliers;
      sum_sq += h * h;
    }
  }
  best.rms = best.inliers > 0 ? std::sqrt(sum_sq / best.inliers) : 0.0;
  return best;
}

}  // namespace sonomap
