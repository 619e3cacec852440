// SPDX-License-Identifier: GPL-3.0-or-later
#include "eval/evaluate_frame.hpp"

#include "core/stopwatch.hpp"
#include "eval/cloud_truth.hpp"

#include <cmath>

namespace sonomap::eval {
namespace {

// Metrics of an estimate with nothing to compare against: only its known cells count.
RasterMetrics without_truth(int estimate_known) {
  RasterMetrics m;
  m.coverage = m.rmse = m.rmse_off_edges = NAN;  // no truth: no error, not zero error
  m.estimate_known = estimate_known;
  return m;
}

void evaluate_edf(const Mapper& mapper, const RasterOrigin& origin, const EvaluationConfig& config,
                  FrameEvaluation& out) {
  const auto t0 = StageClock::now();
  out.edf = edf_raster(mapper, origin, config.raster.azimuth_bins, config.edf);
  out.times.emplace_back("edf", ms_since(t0));
  out.slip = slip_stats(*out.edf);
  if (out.has_truth) {
    out.edf_circle = compare(out.edf->traced, out.truth.circle, config.metrics);
  } else {
    out.edf_circle = without_truth(out.edf->traced.known_count());
  }
}

}  // namespace

FrameEvaluation evaluate_frame(const Circle& circle, const Cylinder& cylinder,
                               const std::optional<FrameTruth>& truth, const Mapper* edf_mapper,
                               const RasterOrigin& origin, const EvaluationConfig& config) {
  FrameEvaluation out;
  out.has_truth = truth.has_value();
  if (truth) {
    const auto t0 = StageClock::now();
    out.truth = truth->cloud ? cloud_truth_rasters(*truth->cloud, truth->origin, config.raster)
                             : ground_truth_rasters(*truth->triangles, truth->origin, config.raster);
    out.times.emplace_back("truth", ms_since(t0));
    out.circle = compare(circle, out.truth.circle, config.metrics);
    out.cylinder = compare(cylinder, out.truth.cylinder, config.metrics);
  } else {
    out.truth = GroundTruthRasters{make_circle(config.raster), make_cylinder(config.raster)};
    out.circle = without_truth(circle.known_count());
    out.cylinder = without_truth(cylinder.known_count());
  }
  if (edf_mapper) evaluate_edf(*edf_mapper, origin, config, out);
  return out;
}

}  // namespace sonomap::eval
