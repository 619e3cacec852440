// SPDX-License-Identifier: GPL-3.0-or-later
// Camera points land where the camera pose puts them in the world, in the voxel that holds
// them; points out of range or not finite are not fused. Truth: Eigen's transform of each
// point, and floor() of its coordinates over the voxel.
#include "../vector_isas.hpp"
#include "core/point_binning.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <numeric>
#include <vector>

using namespace sonomap;

namespace {

// A camera at (1, 2, 1.52) looking along world +x (its optical z), image x to world -y.
Eigen::Isometry3d camera_pose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = -Eigen::Vector3d::UnitY();  // image x: world -y
  pose.linear().col(1) = -Eigen::Vector3d::UnitZ();  // image y (down): world -z
  pose.linear().col(2) = Eigen::Vector3d::UnitX();   // optical axis: world +x
  pose.translation() = Eigen::Vector3d(1.0, 2.0, 1.52);
  return pose;
}

}  // namespace

TEST_CASE("A point 2.02 m in front of the camera lands 2.02 m ahead of it in the world, in its voxel",
          "[point_binning]") {
  const PointBinner binner(0.05, 0.3, 5.0, camera_pose());
  PointBinner::Batch b;
  const Eigen::Vector3f ahead(0.12f, 0.0f, 2.02f);  // 12 cm right of the optical axis
  binner.bin(&ahead, 1, b);
  REQUIRE(b.fused[0] == 1);
  CHECK(b.x[0] == Approx(3.02));
  CHECK(b.y[0] == Approx(1.88));
  CHECK(b.z[0] == Approx(1.52));
  CHECK(b.voxel(0) == openvdb::Coord(60, 37, 30));  // 60.4, 37.6, 30.4 voxels
}

TEST_CASE("Points nearer than the minimum range, beyond the maximum or not finite are not fused",
          "[point_binning]") {
  const PointBinner binner(0.05, 0.3, 5.0, camera_pose());
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Eigen::Vector3f> points{{0, 0, 0.2f}, {0, 0, 0.3f}, {0, 3, 4}, {0, 3.01f, 4},
                                            {nan, 0, 1}, {0, inf, 1}, {0, 0, -inf}};
  PointBinner::Batch b;
  binner.bin(points.data(), points.size(), b);
  const std::vector<int64_t> fused(b.fused, b.fused + points.size());
  CHECK(fused == std::vector<int64_t>{0, 1, 1, 0, 0, 0, 0});
  for (size_t i = 0; i < points.size(); ++i)  // wherever (or nowhere) it lies, not a voxel's index
    if (!b.fused[i]) CHECK(b.voxel(i) == openvdb::Coord(0));
}

TEST_CASE("A full batch places every point as the camera pose does, lane by lane", "[point_binning]") {
  const Eigen::Isometry3d pose = camera_pose();
  const double voxel = 0.05;
  const PointBinner binner(voxel, 0.0, 100.0, pose);
  std::vector<Eigen::Vector3f> points;
  for (size_t i = 0; i < PointBinner::kBatch; ++i)
    points.emplace_back(0.37f * std::sin(0.1f * i), 0.21f * std::cos(0.3f * i) - 0.5f, 0.5f + 0.013f * i);
  PointBinner::Batch b;
  binner.bin(points.data(), points.size(), b);
  for (size_t i = 0; i < points.size(); ++i) {
    INFO("point " << i);
    const Eigen::Vector3d world = pose * points[i].cast<double>();
    REQUIRE(b.fused[i] == 1);
    CHECK(b.x[i] == Approx(world.x()).margin(1e-6));
    CHECK(b.y[i] == Approx(world.y()).margin(1e-6));
    CHECK(b.z[i] == Approx(world.z()).margin(1e-6));
    const Eigen::Vector3d cell = (Eigen::Vector3d(b.x[i], b.y[i], b.z[i]) / voxel).array().floor();
    // The voxel comes from the double position; its float copy may round across a face.
    CHECK((Eigen::Vector3d(b.voxel(i).x(), b.voxel(i).y(), b.voxel(i).z()) - cell).cwiseAbs().maxCoeff() <= 1.0);
  }
}

TEST_CASE("The baseline, AVX2 and AVX-512 copies of the batch pass bin a batch to the same bit",
          "[point_binning]") {
  // A full batch at a pose that is not axis-aligned (each product rounds), with points out of
  // range and not finite among them.
  Eigen::Isometry3d pose = camera_pose();
  pose.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  const PointBinner binner(0.05, 0.3, 5.0, pose);
  std::vector<Eigen::Vector3f> points;
  for (size_t i = 0; i < PointBinner::kBatch; ++i)
    points.emplace_back(1.7f * std::sin(0.7f * i), 1.1f * std::cos(0.3f * i), 0.02f * i);
  points[5].y() = std::numeric_limits<float>::quiet_NaN();
  const auto binned = [&](VectorIsa isa) {
    const ScopedVectorIsa code(isa);
    PointBinner::Batch b;
    binner.bin(points.data(), points.size(), b);
    return b;
  };
  const PointBinner::Batch baseline = binned(VectorIsa::Baseline);
  const int64_t fused = std::accumulate(baseline.fused, baseline.fused + PointBinner::kBatch, int64_t{0});
  CHECK(fused > 100);
  CHECK(fused < 250);
  for (VectorIsa isa : vector_isas_beside_baseline()) {
    INFO(name_of(isa));
    const PointBinner::Batch copy = binned(isa);
    // Every array of the batch: positions, voxels and flags.
    CHECK(std::memcmp(&copy, &baseline, sizeof copy) == 0);
  }
}
