// SPDX-License-Identifier: GPL-3.0-or-later
// A carving ray walks through the voxels (and the 8-voxel blocks) it crosses, in order, and
// through no other. Truth: the cells counted by hand for rays along the axes, and for any ray
// openvdb's own DDA, which the carving used before and whose maps it must reproduce to the bit.
#include "core/grid_walk.hpp"

#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>

#include <catch2/catch.hpp>
#include <random>
#include <vector>

using namespace sonomap;

namespace {

struct Step {
  openvdb::Coord cell;
  double time, next;
  bool operator==(const Step& o) const { return cell == o.cell && time == o.time && next == o.next; }
};

template <int Log2Dim>
std::vector<Step> walk(const Eigen::Vector3d& eye, const Eigen::Vector3d& dir, double t0, double t1) {
  std::vector<Step> steps;
  GridWalk<Log2Dim> w(eye, dir, t0, t1);
  do steps.push_back({w.cell(), w.time(), w.next()});
  while (w.step() && steps.size() < 10000);
  return steps;
}

template <int Log2Dim>
std::vector<Step> openvdb_walk(const Eigen::Vector3d& eye, const Eigen::Vector3d& dir, double t0, double t1) {
  using Ray = openvdb::math::Ray<double>;
  const Ray ray(openvdb::Vec3d(eye.x(), eye.y(), eye.z()), openvdb::Vec3d(dir.x(), dir.y(), dir.z()), t0, t1);
  openvdb::math::DDA<Ray, Log2Dim> dda(ray);
  std::vector<Step> steps;
  do steps.push_back({dda.voxel(), dda.time(), dda.next()});
  while (dda.step() && steps.size() < 10000);
  return steps;
}

// Reproducible values in [-1, 1): std::mt19937_64's output is fixed by the standard (its
// distributions are not, so none is used).
double signed_unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) / (1ull << 52) - 1.0; }

}  // namespace

TEST_CASE("A ray along +x from the middle of voxel 0 to 3.2 voxels on crosses voxels 0 to 3, in order",
          "[grid_walk]") {
  const std::vector<Step> steps = walk<0>({0.5, 0.5, 0.5}, {1.0, 0.0, 0.0}, 0.0, 3.2);
  REQUIRE(steps.size() == 4);
  for (int i = 0; i < 4; ++i) {
    CHECK(steps[i].cell == openvdb::Coord(i, 0, 0));
    CHECK(steps[i].time == Approx(i == 0 ? 0.0 : i - 0.5));  // entered at its face
  }
  CHECK(steps.back().next == Approx(3.2));  // the walk ends at t1, inside voxel 3
}

TEST_CASE("A ray along -y through 8-voxel blocks enters each block at its face, 8 voxels apart",
          "[grid_walk]") {
  const std::vector<Step> steps = walk<3>({3.0, 20.0, -5.0}, {0.0, -1.0, 0.0}, 0.0, 30.0);
  // From y = 20 (block 16..23) down to y = -10 (block -16..-9): blocks 16, 8, 0, -8, -16.
  REQUIRE(steps.size() == 5);
  for (size_t i = 0; i < steps.size(); ++i) {
    CHECK(steps[i].cell == openvdb::Coord(0, 16 - 8 * static_cast<int>(i), -8));
    if (i > 0) CHECK(steps[i].time == Approx(4.0 + 8.0 * (i - 1)));
  }
}

TEST_CASE("Any ray walks the cells, entry times and exits of openvdb's DDA to the bit, ties included",
          "[grid_walk]") {
  std::mt19937_64 rng(20261127);
  for (int i = 0; i < 2000; ++i) {
    Eigen::Vector3d eye(signed_unit(rng) * 40.0, signed_unit(rng) * 40.0, signed_unit(rng) * 40.0);
    Eigen::Vector3d dir(signed_unit(rng), signed_unit(rng), signed_unit(rng));
    if (i % 4 == 1) eye = eye.array().round();  // starting on cell corners and faces
    if (i % 5 == 2) dir[i % 3] = 0.0;           // parallel to one axis
    if (i % 7 == 3) dir = Eigen::Vector3d(1.0, -1.0, 1.0);  // through edges and corners: ties
    if (dir.isZero()) dir.x() = 1.0;
    dir.normalize();
    const double t0 = i % 3 == 0 ? 0.0 : std::abs(signed_unit(rng)) * 5.0;
    const double t1 = t0 + std::abs(signed_unit(rng)) * 60.0;
    INFO("ray " << i);
    CHECK(walk<0>(eye, dir, t0, t1) == openvdb_walk<0>(eye, dir, t0, t1));
    CHECK(walk<3>(eye, dir, t0, t1) == openvdb_walk<3>(eye, dir, t0, t1));
  }
}
