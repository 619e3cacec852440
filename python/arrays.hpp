// SPDX-License-Identifier: GPL-3.0-or-later
// numpy <-> sonomap data for the Python module: rasters as float64 arrays with NaN for an
// unknown cell, poses as 4x4 float64 matrices, the depth image with NaN for "no return".
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace sonomap::python {

namespace py = pybind11;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// (bins,) and (rows, bins): the cells' ranges, NaN where unknown.
py::array_t<double> circle_array(const Circle& circle);
py::array_t<double> cylinder_array(const Cylinder& cylinder);

// An estimate from Python: ranges in metres, NaN = unknown. ValueError naming `what` and the
// index for a wrong shape, a negative or an infinite range.
Circle circle_from_array(const DoubleArray& ranges, const RasterConfig& config);
// A circle of any number of bins (a sweep's input).
Circle circle_from_array(const DoubleArray& ranges);
Cylinder cylinder_from_array(const DoubleArray& ranges, const RasterConfig& config);

py::array_t<double> matrix_array(const Eigen::Isometry3d& pose);

// (height, width) float32 z-depth in metres, NaN where the frame has no return (0).
py::array_t<float> depth_array(const Frame& frame);
// (N, 3) float32: the valid returns in the camera optical frame.
py::array_t<float> points_array(const Frame& frame);

}  // namespace sonomap::python
