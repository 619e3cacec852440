// SPDX-License-Identifier: GPL-3.0-or-later
#include "eval/metrics.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::eval {

bool is_ghost(const RasterCell& estimate, const RasterCell& truth, double tolerance) {
  if (!estimate.known()) return false;
  if (!truth.known()) return true;
  return static_cast<double>(truth.range) - static_cast<double>(estimate.range) > tolerance;
}

RasterMetrics compare_cells(const std::vector<RasterCell>& estimate,
                            const std::vector<RasterCell>& truth, const MetricsConfig& config,
                            int row_width) {
  if (estimate.size() != truth.size()) {
    throw std::invalid_argument("metrics: estimate has " + std::to_string(estimate.size()) +
                                " cells, truth has " + std::to_string(truth.size()));
  }
  if (!std::isfinite(config.ghost_tolerance) || config.ghost_tolerance < 0.0) {
    throw std::invalid_argument("metrics: ghost_tolerance must be finite and >= 0");
  }
  if (row_width < 0 || (row_width > 0 && truth.size() % static_cast<size_t>(row_width) != 0))
    throw std::invalid_argument("metrics: row width " + std::to_string(row_width) +
                                " does not divide " + std::to_string(truth.size()) + " cells");
  const auto on_edge = [&](size_t i) {
    if (row_width == 0) return false;
    const size_t w = static_cast<size_t>(row_width), row = i / w * w, k = i % w;
    for (size_t n : {row + (k + w - 1) % w, row + (k + 1) % w}) {
      if (!truth[n].known() || std::abs(truth[n].range - truth[i].range) > config.edge_jump) return true;
    }
    return false;
  };
  RasterMetrics m;
  m.cells = static_cast<int>(truth.size());
  double squared_error_sum = 0.0, off_edge_sum = 0.0;
  int off_edge_count = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const RasterCell& e = estimate[i];
    const RasterCell& t = truth[i];
    const bool edge = t.known() && on_edge(i);
    if (t.known()) ++m.truth_occupied;
    if (edge) ++m.edge_cells;
    if (!e.known()) continue;
    ++m.estimate_known;
    m.ghosts += is_ghost(e, t, config.ghost_tolerance);
    if (!t.known()) continue;
    ++m.known_in_both;
    const double error = static_cast<double>(e.range) - static_cast<double>(t.range);
    squared_error_sum += error * error;
    if (!edge) off_edge_sum += error * error, ++off_edge_count;
  }
  m.coverage = m.truth_occupied > 0 ? static_cast<double>(m.known_in_both) / m.truth_occupied : NAN;
  m.rmse = m.known_in_both > 0 ? std::sqrt(squared_error_sum / m.known_in_both) : NAN;
  m.rmse_off_edges = off_edge_count > 0 ? std::sqrt(off_edge_sum / off_edge_count) : NAN;
  return m;
}

RasterMetrics compare(const Circle& estimate, const Circle& truth, const MetricsConfig& config) {
  return compare_cells(estimate.bins, truth.bins, config, truth.size());
}

RasterMetrics compare(const Cylinder& estimate, const Cylinder& truth,
                      const MetricsConfig& config) {
  if (estimate.azimuth_bins != truth.azimuth_bins || estimate.rows != truth.rows) {
    throw std::invalid_argument("metrics: cylinders differ in shape (" +
                                std::to_string(estimate.azimuth_bins) + "x" +
                                std::to_string(estimate.rows) + " vs " +
                                std::to_string(truth.azimuth_bins) + "x" +
                                std::to_string(truth.rows) + ")");
  }
  return compare_cells(estimate.cells, truth.cells, config, truth.azimuth_bins);
}

}  // namespace sonomap::eval
