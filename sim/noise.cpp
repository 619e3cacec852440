// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/noise.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace sonomap::sim {

namespace {

// Keeps the grazing terms finite when a surface is seen exactly edge-on.
constexpr double kMaxTheta = M_PI / 2 - 1e-3;


// Round half up; offsets are small, so the int conversion cannot overflow after the clamp.
int nearest_int(double x) { return static_cast<int>(std::floor(std::clamp(x, -1e6, 1e6) + 0.5)); }

RandomStream row_stream(const NoiseKey& key, StreamPurpose purpose, int row) {
  return RandomStream({key.seed, key.sensor, key.frame, static_cast<std::uint64_t>(purpose),
                       static_cast<std::uint64_t>(row)});
}

// Runs body(row) for every row, rows spread over TBB threads.
template <typename Body>
void for_each_row(int height, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v < rows.end(); ++v) body(v);
  });
}

}  // namespace

double axial_sigma(double z, double theta) {
  double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
  if (theta > M_PI / 3) {
    const double t = std::min(theta, kMaxTheta);
    sigma += 0.0001 / std::sqrt(z) * t * t / ((M_PI / 2 - t) * (M_PI / 2 - t));
  }
  return sigma;
}

double lateral_sigma_px(double theta) {
  const double t = std::min(theta, kMaxTheta);
  return 0.8 + 0.035 * t / (M_PI / 2 - t);
}

DepthImage jitter_lateral(const DepthImage& in, const NoiseKey& key) {
  DepthImage out;  // every pixel is written below
  out.width = in.width;
  out.height = in.height;
  out.z.resize(in.z.size());
  out.incidence.resize(in.incidence.size());
  for_each_row(in.height, [&](int v) {
    RandomStream rng = row_stream(key, StreamPurpose::LateralJitter, v);
    const std::size_t row = static_cast<std::size_t>(v) * in.width;
    for (int u = 0; u < in.width; ++u) {
      const double sigma = lateral_sigma_px(in.incidence[row + u]);
      const int su = std::clamp(u + nearest_int(rng.normal(sigma)), 0, in.width - 1);
      const int sv = std::clamp(v + nearest_int(rng.normal(sigma)), 0, in.height - 1);
      const std::size_t source = static_cast<std::size_t>(sv) * in.width + su;
      out.z[row + u] = in.z[source];
      out.incidence[row + u] = in.incidence[source];
    }
  });
  return out;
}

namespace {

// The stages after the lateral jitter change pixels in place: apply_noise runs them on one
// image instead of copying it per stage. The public functions below wrap them.

void axial_in_place(DepthImage& image, const NoiseKey& key) {
  for_each_row(image.height, [&](int v) {
    RandomStream rng = row_stream(key, StreamPurpose::AxialNoise, v);
    const std::size_t row = static_cast<std::size_t>(v) * image.width;
    for (int u = 0; u < image.width; ++u) {
      float& z = image.z[row + u];
      if (!(z > 0.0f)) continue;
      const double noisy = z + rng.normal(axial_sigma(z, image.incidence[row + u]));
      z = noisy > 0.0 ? static_cast<float>(noisy) : 0.0f;
    }
  });
}

void quantise_in_place(DepthImage& image, double focal_px, double baseline, double step) {
  const double fb = focal_px * baseline;
  for_each_row(image.height, [&](int v) {
    float* row = image.z.data() + static_cast<std::size_t>(v) * image.width;
    for (int u = 0; u < image.width; ++u) {
      if (!(row[u] > 0.0f)) continue;
      const double steps = std::round(fb / (row[u] * step));
      row[u] = steps > 0.0 ? static_cast<float>(fb / (steps * step)) : 0.0f;
    }
  });
}

void grazing_in_place(DepthImage& image, double max_angle) {
  for (std::size_t p = 0; p < image.z.size(); ++p)
    if (image.incidence[p] > max_angle) image.z[p] = 0.0f;
}

void edges_in_place(DepthImage& image, const DepthImage& reference, double threshold) {
  const int w = reference.width, h = reference.height;
  auto depth = [&](int u, int v) {  // no surface counts as infinitely far
    const float z = reference.z[static_cast<std::size_t>(v) * w + u];
    return z > 0.0f ? static_cast<double>(z) : HUGE_VAL;
  };
  for_each_row(h, [&](int v) {
    for (int u = 0; u < w; ++u) {
      const double z = depth(u, v);
      if (z == HUGE_VAL) continue;
      const bool edge = (u > 0 && std::abs(depth(u - 1, v) - z) > threshold) ||
                        (u + 1 < w && std::abs(depth(u + 1, v) - z) > threshold) ||
                        (v > 0 && std::abs(depth(u, v - 1) - z) > threshold) ||
                        (v + 1 < h && std::abs(depth(u, v + 1) - z) > threshold);
      if (edge) image.z[static_cast<std::size_t>(v) * w + u] = 0.0f;
    }
  });
}

void drop_out_in_place(DepthImage& image, double p, const NoiseKey& key) {
  if (p <= 0.0) return;
  for_each_row(image.height, [&](int v) {
    RandomStream rng = row_stream(key, StreamPurpose::Dropout, v);
    float* row = image.z.data() + static_cast<std::size_t>(v) * image.width;
    for (int u = 0; u < image.width; ++u)
      if (rng.uniform() < p) row[u] = 0.0f;  // drawn for every pixel so streams stay aligned
  });
}

// A copy of `in` with `stage` applied to it.
template <typename Stage>
DepthImage changed(DepthImage image, const Stage& stage) {
  stage(image);
  return image;
}

}  // namespace

DepthImage add_axial_noise(const DepthImage& in, const NoiseKey& key) {
  return changed(in, [&](DepthImage& image) { axial_in_place(image, key); });
}

DepthImage quantise_disparity(const DepthImage& in, double focal_px, double baseline, double step) {
  return changed(in, [&](DepthImage& image) { quantise_in_place(image, focal_px, baseline, step); });
}

DepthImage invalidate_grazing(const DepthImage& in, double max_angle) {
  return changed(in, [&](DepthImage& image) { grazing_in_place(image, max_angle); });
}

DepthImage invalidate_edges(const DepthImage& in, const DepthImage& reference, double threshold) {
  return changed(in, [&](DepthImage& image) { edges_in_place(image, reference, threshold); });
}

DepthImage drop_out(const DepthImage& in, double p, const NoiseKey& key) {
  return changed(in, [&](DepthImage& image) { drop_out_in_place(image, p, key); });
}

DepthImage apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key) {
  if (spec.model == NoiseSpec::Model::None) return truth;
  DepthImage image = spec.lateral ? jitter_lateral(truth, key) : truth;
  if (spec.axial) axial_in_place(image, key);
  if (spec.quantisation) quantise_in_place(image, focal_px, spec.baseline, spec.disparity_step);
  if (spec.grazing_invalidation) grazing_in_place(image, spec.grazing_angle);
  if (spec.edge_invalidation) edges_in_place(image, truth, spec.edge_threshold);
  drop_out_in_place(image, spec.dropout, key);
  return image;
}

}  // namespace sonomap::sim
