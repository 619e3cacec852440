// SPDX-License-Identifier: GPL-3.0-or-later
// The paper's "Compare to EDF" baseline: the circle read from a Euclidean distance field
// instead of from the map's surface points. Per azimuth bin (same bins and azimuth convention
// as the circle, docs/conventions.md), on the horizontal plane through the sensor:
//  (a) the field at the bin's point on a circle of `sample_radius` around the sensor: its
//      distance and its bearing slip, the angle between the direction to the closest surface
//      (-gradient) and the bin's outward ray. The field points to whatever surface is closest,
//      so the slip is large wherever that is not the one straight along the ray (the paper's
//      Fig. "arrow_esdf": such bearings do not run round the listener in order);
//  (b) the range along the bin's ray found by sphere tracing the field, a circle built from
//      the EDF alone, to compare with the map's circle against the same ground truth. The
//      circle holds obstacles anywhere in a height band, so rays can be traced at several
//      heights (trace_heights) and the bin keeps the nearest hit.
// Where the field is unobserved the values are unknown (NaN / kUnknownRange), never guessed.
#pragma once

#include "core/mapper.hpp"
#include "core/raster.hpp"
#include "core/types.hpp"

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace sonomap {

struct EdfRasterConfig {
  double sample_radius = 1.0;   // m: the circle of query points around the sensor
  double hit_tolerance = 0.05;  // m: a traced ray has hit when the field reads below this
  int max_steps = 64;           // sphere-tracing iterations before a ray gives up (unknown)
  double max_range = 5.0;       // m: a ray that gets this far without a hit is unknown
  // Heights above the ground (origin.ground_z) of the horizontal rays traced per bin; empty:
  // one ray at the sensor's height. The sample circle is always at the sensor's height.
  std::vector<double> trace_heights;
  // Throws std::invalid_argument naming the field unless every value is finite and positive
  // (trace heights: finite) and max_steps >= 1.
  void validate() const;
};

// How a sphere-traced ray ended.
enum class TraceEnd {
  Hit,         // the field fell below hit_tolerance: the range is known
  Unobserved,  // the ray reached a point the map knows nothing about
  OutOfRange,  // no hit within max_range
  StepLimit,   // still marching after max_steps (grazing a surface)
};

// "hit", "unobserved", "out_of_range", "step_limit".
const char* trace_end_name(TraceEnd end);

struct EdfBin {
  // (a) The field at the sample point; NaN where unobserved.
  bool sample_observed = false;
  float sample_distance = NAN;  // m
  float slip_deg = NAN;         // in [0, 180]
  Eigen::Vector3f sample_point = Eigen::Vector3f::Constant(NAN);       // world
  Eigen::Vector3f closest_direction = Eigen::Vector3f::Constant(NAN);  // unit, -gradient, world
  // (b) Sphere tracing; the range (and hit point) lives in EdfRaster::traced. With several
  // trace heights: Hit if any ray hit, else StepLimit, Unobserved, OutOfRange in that order
  // (the first that any of its rays met).
  TraceEnd end = TraceEnd::Unobserved;
  int steps = 0;  // the most field queries any of the bin's rays spent
};

struct EdfRaster {
  std::vector<EdfBin> bins;  // azimuth_bins entries, bin k centred at (k + 0.5) * 360 / bins
  Circle traced;             // the sphere-traced circle: range and hit point where known
};

// The EDF variant of the circle around `origin` (its position is the sensor: the plane of the
// circle is at origin.position.z). One Mapper::query call for all sample points, then one per
// sphere-tracing iteration for all still-active rays (every bin and height), so the result does not depend on how
// the mapper parallelises its queries. Throws std::invalid_argument on an invalid config,
// azimuth_bins outside [1, 36000] or a non-finite origin (position, heading, ground height).
EdfRaster edf_raster(const Mapper& mapper, const RasterOrigin& origin, int azimuth_bins,
                     const EdfRasterConfig& config = {});

// Median and 90th percentile of the slip over the bins where it is known (nearest rank:
// the value with ceil(q n) - 1 values below it in sorted order); NaN when none is.
struct SlipStats {
  int observed = 0;
  double median_deg = NAN;
  double p90_deg = NAN;
};
SlipStats slip_stats(const EdfRaster& raster);

}  // namespace sonomap
