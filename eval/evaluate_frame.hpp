// SPDX-License-Identifier: GPL-3.0-or-later
// One frame's evaluation: the exact ground-truth rasters, the metrics of the estimated circle
// and cylinder against them, and (when a mapper with a field is given) the EDF comparison.
// Whoever made the estimate, a built-in mapper during `run` or any program's rasters read
// back from files, is judged by this one function. Pure: no I/O.
#pragma once

#include "core/edf_raster.hpp"
#include "core/mapper.hpp"
#include "core/raster.hpp"
#include "core/types.hpp"
#include "eval/ground_truth.hpp"
#include "eval/metrics.hpp"
#include "eval/moved_ghosts.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sonomap::eval {

// The scene at the frame's instant, seen from the TRUE body pose (never the estimate): its
// exact triangles, or a reference point cloud (eval/cloud_truth.hpp) when `cloud` is set.
struct FrameTruth {
  const std::vector<GroundTruthTriangle>* triangles = nullptr;
  RasterOrigin origin;
  const std::vector<Eigen::Vector3f>* cloud = nullptr;
};

struct EvaluationConfig {
  RasterConfig raster;
  MetricsConfig metrics;
  EdfRasterConfig edf;
};

struct FrameEvaluation {
  bool has_truth = false;
  // Unknown everywhere without truth (recorded data), and then the metrics are undefined:
  // coverage and RMSE NaN, the counts of known estimate cells filled in.
  GroundTruthRasters truth;
  RasterMetrics circle, cylinder;
  // The EDF comparison, when a mapper was given: the sphere-traced circle, its metrics
  // against the truth (NaN without truth) and the bearing slip (which needs no truth).
  std::optional<EdfRaster> edf;
  RasterMetrics edf_circle;
  SlipStats slip;
  // The moved objects' ghosts in the circle, when the run tracks them (eval/moved_ghosts.hpp:
  // the tracker keeps state across frames, so the run adds this after evaluate_frame).
  std::optional<MovedGhostFrame> moved;
  // Wall time of the stages, milliseconds: "truth" (with truth), "edf" (with a mapper).
  std::vector<std::pair<std::string, double>> times;
};

// `circle` and `cylinder`: the estimate around `origin` (the estimated pose). `truth`: none
// for recorded data. `edf_mapper`: the map whose field the EDF circle is traced in around
// `origin`; null for no EDF comparison. Throws std::invalid_argument on an invalid config or
// a non-finite origin or triangle.
FrameEvaluation evaluate_frame(const Circle& circle, const Cylinder& cylinder,
                               const std::optional<FrameTruth>& truth, const Mapper* edf_mapper,
                               const RasterOrigin& origin, const EvaluationConfig& config);

}  // namespace sonomap::eval
