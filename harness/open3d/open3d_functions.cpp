// SPDX-License-Identifier: GPL-3.0-or-later
// libsonomap_open3d_io.so: everything the harness takes from Open3D, behind one entry point
// (harness/formats/modules.hpp explains why it is loaded on demand).
#include "harness/formats/modules.hpp"
#include "harness/support/errors.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/utility/Logging.h>

#include <cmath>

namespace sonomap::harness {

namespace {

std::unique_ptr<Mapper> make_mapper(const Open3dTsdfConfig& config) {
  return std::make_unique<Open3dTsdf>(config);
}

const Open3dTsdfConfig* config_of(const Mapper& mapper) {
  const auto* open3d = dynamic_cast<const Open3dTsdf*>(&mapper);
  return open3d ? &open3d->config() : nullptr;
}

// Open3D reports a failure through its logger (a warning) or by throwing: silence the logger
// and say it ourselves, naming the file.
std::vector<Eigen::Vector3f> read_point_cloud(const std::filesystem::path& file) {
  open3d::geometry::PointCloud loaded;
  bool ok = false;
  std::string reason = "expected a PLY, PCD or XYZ file";
  open3d::utility::VerbosityContextManager silence(open3d::utility::VerbosityLevel::Error);
  silence.Enter();
  try {
    ok = open3d::io::ReadPointCloud(file.string(), loaded);
  } catch (const std::exception& e) {
    reason = e.what();
  }
  silence.Exit();
  const std::string name = file.string();
  if (!ok) throw InputError(name, 0, "", "cannot read the point cloud (" + reason + ")");
  if (loaded.points_.empty()) throw InputError(name, 0, "", "the point cloud has no points");
  std::vector<Eigen::Vector3f> points;
  points.reserve(loaded.points_.size());
  for (size_t i = 0; i < loaded.points_.size(); ++i) {
    if (!loaded.points_[i].allFinite())
      throw InputError(name, 0, "", "point " + std::to_string(i) + " is not finite (NaN or inf)");
    points.push_back(loaded.points_[i].cast<float>());
  }
  return points;
}

std::vector<double> nearest_distances(const std::vector<Eigen::Vector3f>& from,
                                      const std::vector<Eigen::Vector3f>& to) {
  std::vector<double> distances;
  if (to.empty()) return distances;
  Eigen::MatrixXd points(3, static_cast<Eigen::Index>(to.size()));
  for (size_t i = 0; i < to.size(); ++i) points.col(static_cast<Eigen::Index>(i)) = to[i].cast<double>();
  const open3d::geometry::KDTreeFlann tree(points);
  distances.reserve(from.size());
  std::vector<int> index;
  std::vector<double> distance2;
  for (const Eigen::Vector3f& p : from)
    if (tree.SearchKNN(Eigen::Vector3d(p.cast<double>()), 1, index, distance2) == 1)
      distances.push_back(std::sqrt(distance2[0]));
  return distances;
}

const Open3dFunctions kFunctions{make_mapper, config_of, read_point_cloud, nearest_distances};

}  // namespace

}  // namespace sonomap::harness

extern "C" const sonomap::harness::Open3dFunctions* sonomap_open3d_functions() {
  return &sonomap::harness::kFunctions;
}
