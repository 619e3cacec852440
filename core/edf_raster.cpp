// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/edf_raster.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sonomap {

void EdfRasterConfig::validate() const {
  auto positive = [](double v, const char* name) {
    if (!std::isfinite(v) || !(v > 0.0))
      throw std::invalid_argument(std::string("edf config: ") + name +
                                  " must be finite and > 0, got " + std::to_string(v));
  };
  positive(sample_radius, "sample_radius");
  positive(hit_tolerance, "hit_tolerance");
  positive(max_range, "max_range");
  for (double h : trace_heights)
    if (!std::isfinite(h))
      throw std::invalid_argument("edf config: trace_heights must be finite, got " + std::to_string(h));
  if (max_steps < 1)
    throw std::invalid_argument("edf config: max_steps must be >= 1, got " +
                                std::to_string(max_steps));
}

const char* trace_end_name(TraceEnd end) {
  switch (end) {
    case TraceEnd::Hit: return "hit";
    case TraceEnd::Unobserved: return "unobserved";
    case TraceEnd::OutOfRange: return "out_of_range";
    case TraceEnd::StepLimit: return "step_limit";
  }
  return "?";
}

namespace {

double degrees_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / M_PI;
}

// Which end describes a bin whose rays ended differently: a hit wins, then the ends that say
// most about the field (it went on too long, or it ran out of map), then "nothing in range".
int precedence(TraceEnd end) {
  switch (end) {
    case TraceEnd::Hit: return 3;
    case TraceEnd::StepLimit: return 2;
    case TraceEnd::Unobserved: return 1;
    case TraceEnd::OutOfRange: return 0;
  }
  return 0;
}

}  // namespace

EdfRaster edf_raster(const Mapper& mapper, const RasterOrigin& origin, int azimuth_bins,
                     const EdfRasterConfig& config) {
  config.validate();
  if (azimuth_bins < 1 || azimuth_bins > 36000)
    throw std::invalid_argument("edf raster: azimuth_bins must be in [1, 36000], got " +
                                std::to_string(azimuth_bins));
  if (!origin.position.allFinite() || !std::isfinite(origin.heading) || !std::isfinite(origin.ground_z))
    throw std::invalid_argument("edf raster: the origin's position, heading and ground height must be finite");
  // One batched query; a mapper that answers a different number of points breaks its contract.
  auto ask = [&mapper](const std::vector<Eigen::Vector3f>& points, std::vector<DistanceQuery>& answers) {
    mapper.query(points, answers);
    if (answers.size() != points.size())
      throw std::logic_error("edf raster: mapper '" + mapper.name() + "' answered " +
                             std::to_string(answers.size()) + " of " + std::to_string(points.size()) +
                             " queries");
  };

  const size_t n = static_cast<size_t>(azimuth_bins);
  EdfRaster out;
  out.bins.resize(n);
  out.traced = Circle(azimuth_bins);
  const double bin_rad = 2.0 * M_PI / azimuth_bins;
  std::vector<Eigen::Vector3d> rays(n);
  for (size_t k = 0; k < n; ++k) {
    const double a = origin.heading + (static_cast<double>(k) + 0.5) * bin_rad;
    rays[k] = Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
  }

  // (a) The field on the sample circle.
  std::vector<Eigen::Vector3f> points(n);
  std::vector<DistanceQuery> answers;
  for (size_t k = 0; k < n; ++k) {
    points[k] = (origin.position + config.sample_radius * rays[k]).cast<float>();
    out.bins[k].sample_point = points[k];
  }
  ask(points, answers);
  for (size_t k = 0; k < n; ++k) {
    const DistanceQuery& q = answers[k];
    const Eigen::Vector3d g = q.gradient.cast<double>();
    // A field without a usable gradient at the point has no direction: unknown, not 0.
    if (!q.observed || !std::isfinite(q.distance) || !g.allFinite() || g.norm() < 1e-6) continue;
    EdfBin& bin = out.bins[k];
    bin.sample_observed = true;
    bin.sample_distance = q.distance;
    const Eigen::Vector3d toward = -g.normalized();
    bin.closest_direction = toward.cast<float>();
    bin.slip_deg = static_cast<float>(degrees_between(toward, rays[k]));
  }

  // (b) Sphere tracing: every ray steps by the field's distance, all active rays (bin x
  // height) in one query per step. Ray r belongs to bin r % n.
  std::vector<Eigen::Vector3d> starts;
  if (config.trace_heights.empty()) starts.push_back(origin.position);
  for (double h : config.trace_heights)
    starts.emplace_back(origin.position.x(), origin.position.y(), origin.ground_z + h);
  const size_t ray_count = n * starts.size();
  std::vector<double> t(ray_count, 0.0);
  std::vector<TraceEnd> ends(ray_count, TraceEnd::StepLimit);
  std::vector<int> steps(ray_count, 0);
  std::vector<size_t> active(ray_count);
  for (size_t r = 0; r < ray_count; ++r) active[r] = r;
  for (int step = 0; step < config.max_steps && !active.empty(); ++step) {
    points.resize(active.size());
    for (size_t i = 0; i < active.size(); ++i) {
      const size_t r = active[i];
      points[i] = (starts[r / n] + t[r] * rays[r % n]).cast<float>();
    }
    ask(points, answers);
    std::vector<size_t> still;
    for (size_t i = 0; i < active.size(); ++i) {
      const size_t r = active[i];
      const DistanceQuery& q = answers[i];
      steps[r] = step + 1;
      if (!q.observed || !std::isfinite(q.distance) || q.distance < 0.0f) {
        ends[r] = TraceEnd::Unobserved;
        continue;
      }
      // The surface is at least the field's distance further on; on a plane hit at any angle
      // t + d is still short of the true hit (t + d / cos), so adding it only removes bias.
      const double reach = t[r] + q.distance;
      if (reach > config.max_range) {
        ends[r] = TraceEnd::OutOfRange;
        continue;
      }
      t[r] = reach;
      if (q.distance < config.hit_tolerance) {
        ends[r] = TraceEnd::Hit;
        continue;
      }
      still.push_back(r);
    }
    active.swap(still);
  }
  for (size_t r = 0; r < ray_count; ++r) {
    const size_t k = r % n;
    EdfBin& bin = out.bins[k];
    RasterCell& cell = out.traced.bins[k];
    bin.steps = std::max(bin.steps, steps[r]);
    if (r < n || precedence(ends[r]) > precedence(bin.end)) bin.end = ends[r];
    if (ends[r] == TraceEnd::Hit && t[r] < cell.range) {
      cell.range = static_cast<float>(t[r]);
      cell.point = (starts[r / n] + t[r] * rays[k]).cast<float>();
    }
  }
  return out;
}

SlipStats slip_stats(const EdfRaster& raster) {
  std::vector<double> slips;
  for (const EdfBin& b : raster.bins)
    if (std::isfinite(b.slip_deg)) slips.push_back(b.slip_deg);
  SlipStats s;
  s.observed = static_cast<int>(slips.size());
  if (slips.empty()) return s;
  std::sort(slips.begin(), slips.end());
  auto nearest_rank = [&](double q) {
    const size_t rank = static_cast<size_t>(std::ceil(q * slips.size()));
    return slips[std::max<size_t>(rank, 1) - 1];
  };
  s.median_deg = nearest_rank(0.5);
  s.p90_deg = nearest_rank(0.9);
  return s;
}

}  // namespace sonomap
