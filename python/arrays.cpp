// SPDX-License-Identifier: GPL-3.0-or-later
#include "python/arrays.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace sonomap::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double cell_value(const RasterCell& cell) { return cell.known() ? cell.range : kNaN; }

// NaN: unknown. The rasters hold float ranges; negative or infinite ones are nobody's estimate.
RasterCell cell_from(double range, const char* what, py::ssize_t index) {
  RasterCell cell;
  if (std::isnan(range)) return cell;
  if (!std::isfinite(range) || range < 0.0)
    throw py::value_error(std::string(what) + "[" + std::to_string(index) + "] = " +
                          std::to_string(range) +
                          ": a range must be finite and >= 0 metres, or NaN (unknown)");
  cell.range = static_cast<float>(range);
  return cell;
}

void check_shape(const DoubleArray& a, const std::vector<py::ssize_t>& shape, const char* what) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (size_t i = 0; ok && i < shape.size(); ++i) ok = a.shape(i) == shape[i];
  if (ok) return;
  std::string want = "(", got = "(";
  for (size_t i = 0; i < shape.size(); ++i) want += (i ? ", " : "") + std::to_string(shape[i]);
  for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
  throw py::value_error(std::string(what) + ": expected shape " + want + "), got " + got + ")");
}

}  // namespace

py::array_t<double> circle_array(const Circle& circle) {
  py::array_t<double> out(circle.size());
  double* p = out.mutable_data();
  for (int k = 0; k < circle.size(); ++k) p[k] = cell_value(circle.bins[k]);
  return out;
}

py::array_t<double> cylinder_array(const Cylinder& cylinder) {
  py::array_t<double> out({cylinder.rows, cylinder.azimuth_bins});
  double* p = out.mutable_data();
  for (size_t i = 0; i < cylinder.cells.size(); ++i) p[i] = cell_value(cylinder.cells[i]);
  return out;
}

Circle circle_from_array(const DoubleArray& ranges, const RasterConfig& config) {
  check_shape(ranges, {config.azimuth_bins}, "circle");
  Circle circle = make_circle(config);
  for (int k = 0; k < circle.size(); ++k) circle.bins[k] = cell_from(ranges.data()[k], "circle", k);
  return circle;
}

Circle circle_from_array(const DoubleArray& ranges) {
  if (ranges.ndim() != 1 || ranges.size() < 1)
    throw py::value_error("circle: expected a 1-D array of at least one bin");
  RasterConfig config;
  config.azimuth_bins = static_cast<int>(ranges.size());
  return circle_from_array(ranges, config);
}

Cylinder cylinder_from_array(const DoubleArray& ranges, const RasterConfig& config) {
  check_shape(ranges, {config.rows(), config.azimuth_bins}, "cylinder");
  Cylinder cylinder = make_cylinder(config);
  for (size_t i = 0; i < cylinder.cells.size(); ++i)
    cylinder.cells[i] = cell_from(ranges.data()[i], "cylinder (flat index)", static_cast<py::ssize_t>(i));
  return cylinder;
}

py::array_t<double> matrix_array(const Eigen::Isometry3d& pose) {
  py::array_t<double> out({4, 4});
  const Eigen::Matrix4d m = pose.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.mutable_at(r, c) = m(r, c);
  return out;
}

py::array_t<float> depth_array(const Frame& frame) {
  py::array_t<float> out({frame.height, frame.width});
  float* p = out.mutable_data();
  for (size_t i = 0; i < frame.depth.size(); ++i)
    p[i] = frame.depth[i] > 0.0f ? frame.depth[i] : std::numeric_limits<float>::quiet_NaN();
  return out;
}

py::array_t<float> points_array(const Frame& frame) {
  const auto n = static_cast<py::ssize_t>(frame.points_camera.size());
  py::array_t<float> out({n, py::ssize_t{3}});
  float* p = out.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) p[3 * i + j] = frame.points_camera[i][j];
  return out;
}

}  // namespace sonomap::python
