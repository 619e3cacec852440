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

// axial_sigma and lateral_sigma_px for the per-pixel loops: a library's exported functions are
// not inlined (they could be interposed), these are.
inline double axial_sigma_of(double z, double theta) {
  double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
  if (theta > M_PI / 3) {
    const double t = std::min(theta, kMaxTheta);
    sigma += 0.0001 / std::sqrt(z) * t * t / ((M_PI / 2 - t) * (M_PI / 2 - t));
  }
  return sigma;
}

inline double lateral_sigma_px_of(double theta) {
  const double t = std::min(theta, kMaxTheta);
  return 0.8 + 0.035 * t / (M_PI / 2 - t);
}

// Round half up (floor(x + 0.5)) without a libm call; offsets are small, so the int
// conversion cannot overflow after the clamp.
int nearest_int(double x) {
  const double y = std::clamp(x, -1e6, 1e6) + 0.5;
  const int i = static_cast<int>(y);  // truncates towards zero
  return i - (y < i);
}

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

// The random numbers of one image row. Every pixel u takes word u of each stream (SplitMix64
// is a counter), so a pixel's noise depends on its key and position only: the same whether the
// stages run one by one or fused, in any order, on any thread, and skipped pixels cost nothing.
struct RowRandom {
  RowRandom(const NoiseKey& key, int row)
      : jitter(row_stream(key, StreamPurpose::LateralJitter, row)),
        axial(row_stream(key, StreamPurpose::AxialNoise, row)) {}
  RandomStream jitter;  // word u: two normals for the offset in u and v
  RandomStream axial;   // word u: low half the axial normal, high half the dropout draw
};

// The pixel whose depth pixel (u, v) takes under lateral jitter, given its incidence.
std::size_t jitter_source(const RowRandom& rng, int u, int v, int width, int height, float incidence) {
  const std::uint64_t word = rng.jitter.bits_at(static_cast<std::uint64_t>(u));
  const std::uint64_t slow = 2 * static_cast<std::uint64_t>(u);
  const double sigma = lateral_sigma_px_of(incidence);
  const float du = rng.jitter.normal32(static_cast<std::uint32_t>(word), slow);
  const float dv = rng.jitter.normal32(static_cast<std::uint32_t>(word >> 32), slow + 1);
  const int su = std::clamp(u + nearest_int(sigma * du), 0, width - 1);
  const int sv = std::clamp(v + nearest_int(sigma * dv), 0, height - 1);
  return static_cast<std::size_t>(sv) * width + su;
}

// z + N(0, axial_sigma) from the low half of the pixel's axial word; <= 0 becomes no return.
float axial_noisy(float z, float incidence, std::uint64_t word, const RowRandom& rng, int u) {
  const float n = rng.axial.normal32(static_cast<std::uint32_t>(word), static_cast<std::uint64_t>(u));
  const double noisy = z + axial_sigma_of(z, incidence) * n;
  return noisy > 0.0 ? static_cast<float>(noisy) : 0.0f;
}

// Dropout with probability p: the high half of the pixel's axial word below p 2^32.
std::uint64_t dropout_threshold(double p) { return static_cast<std::uint64_t>(std::clamp(p, 0.0, 1.0) * 0x1.0p32); }
bool dropped(std::uint64_t word, std::uint64_t threshold) { return (word >> 32) < threshold; }

// Depth measured as a whole number of disparity steps (fb = focal length x baseline).
// Branch-free so that a row's loop vectorises; no return (z = 0) stays 0.
float quantised(float z, double fb, double step) {
  // Round half up; the step count is positive, so truncation is floor (z = 0 gives 1e9 + 0.5).
  const double steps = static_cast<double>(static_cast<std::int32_t>(std::min(fb / (z * step), 1e9) + 0.5));
  return z > 0.0f && steps > 0.0 ? static_cast<float>(fb / (steps * step)) : 0.0f;
}

}  // namespace

double axial_sigma(double z, double theta) { return axial_sigma_of(z, theta); }

double lateral_sigma_px(double theta) { return lateral_sigma_px_of(theta); }

namespace {

// The stages on one image row: z and incidence point at the row's first pixel of the image
// being changed. Each is a short loop of its own (pipelines and, for quantisation, vectorises
// better than one loop with every stage's branches).

// The row of `in` under lateral jitter, into z and incidence (which do not alias `in`).
void jitter_row(const DepthImage& in, const RowRandom& rng, int v, float* __restrict z, float* __restrict incidence) {
  const float* __restrict in_z = in.z.data();
  const float* __restrict in_incidence = in.incidence.data();
  const float* row_incidence = in_incidence + static_cast<std::size_t>(v) * in.width;
  for (int u = 0; u < in.width; ++u) {
    const std::size_t source = jitter_source(rng, u, v, in.width, in.height, row_incidence[u]);
    z[u] = in_z[source];
    incidence[u] = in_incidence[source];
  }
}

// Axial noise (if `axial`) and dropout with probability threshold / 2^32 from the same words;
// a dropped pixel skips the axial sample.
void axial_dropout_row(const RowRandom& rng, int width, bool axial, std::uint64_t threshold, float* __restrict z,
                       const float* __restrict incidence) {
  for (int u = 0; u < width; ++u) {
    if (!(z[u] > 0.0f)) continue;
    const std::uint64_t word = rng.axial.bits_at(static_cast<std::uint64_t>(u));
    if (dropped(word, threshold))
      z[u] = 0.0f;
    else if (axial)
      z[u] = axial_noisy(z[u], incidence[u], word, rng, u);
  }
}

void quantise_row(int width, double fb, double step, float* z) {
  for (int u = 0; u < width; ++u) z[u] = quantised(z[u], fb, step);
}

void grazing_row(int width, double max_angle, float* z, const float* incidence) {
  for (int u = 0; u < width; ++u) z[u] = incidence[u] > max_angle ? 0.0f : z[u];
}

void edges_row(const DepthImage& reference, int v, double threshold, float* z) {
  const int w = reference.width;
  const float* truth = reference.z.data() + static_cast<std::size_t>(v) * w;
  const float* above = v > 0 ? truth - w : truth;  // the image's border repeats: no difference
  const float* below = v + 1 < reference.height ? truth + w : truth;
  // A neighbour n differs from z: no surface there, or more than threshold nearer or farther.
  auto differs = [&](float n, float z0) { return !(n > 0.0f) || std::abs(static_cast<double>(n) - z0) > threshold; };
  for (int u = 0; u < w; ++u) {
    const float z0 = truth[u];
    const bool edge = differs(truth[u > 0 ? u - 1 : u], z0) | differs(truth[u + 1 < w ? u + 1 : u], z0) |
                      differs(above[u], z0) | differs(below[u], z0);
    z[u] = z0 > 0.0f && edge ? 0.0f : z[u];
  }
}

// Runs stage(rng, row z, row incidence, v) on every row of `image`, rows over TBB threads.
template <typename Stage>
void each_row(DepthImage& image, const NoiseKey& key, const Stage& stage) {
  for_each_row(image.height, [&](int v) {
    const std::size_t row = static_cast<std::size_t>(v) * image.width;
    stage(RowRandom(key, v), image.z.data() + row, image.incidence.data() + row, v);
  });
}

// A copy of `in` with `stage` applied to every row.
template <typename Stage>
DepthImage changed(DepthImage image, const NoiseKey& key, const Stage& stage) {
  each_row(image, key, stage);
  return image;
}

DepthImage sized_like(const DepthImage& in) {
  DepthImage out;
  out.width = in.width;
  out.height = in.height;
  out.z.resize(in.z.size());
  out.incidence.resize(in.incidence.size());
  return out;
}

}  // namespace

DepthImage jitter_lateral(const DepthImage& in, const NoiseKey& key) {
  DepthImage out = sized_like(in);  // every pixel is written by jitter_row
  each_row(out, key, [&](const RowRandom& rng, float* z, float* incidence, int v) { jitter_row(in, rng, v, z, incidence); });
  return out;
}

DepthImage add_axial_noise(const DepthImage& in, const NoiseKey& key) {
  return changed(in, key, [&](const RowRandom& rng, float* z, float* incidence, int) {
    axial_dropout_row(rng, in.width, true, 0, z, incidence);
  });
}

DepthImage quantise_disparity(const DepthImage& in, double focal_px, double baseline, double step) {
  return changed(in, NoiseKey{}, [&](const RowRandom&, float* z, float*, int) { quantise_row(in.width, focal_px * baseline, step, z); });
}

DepthImage invalidate_grazing(const DepthImage& in, double max_angle) {
  return changed(in, NoiseKey{}, [&](const RowRandom&, float* z, float* incidence, int) { grazing_row(in.width, max_angle, z, incidence); });
}

DepthImage invalidate_edges(const DepthImage& in, const DepthImage& reference, double threshold) {
  return changed(in, NoiseKey{}, [&](const RowRandom&, float* z, float*, int v) { edges_row(reference, v, threshold, z); });
}

DepthImage drop_out(const DepthImage& in, double p, const NoiseKey& key) {
  return changed(in, key, [&](const RowRandom& rng, float* z, float* incidence, int) {
    axial_dropout_row(rng, in.width, false, dropout_threshold(p), z, incidence);
  });
}

void apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key,
                 DepthImage& out) {
  if (spec.model == NoiseSpec::Model::None) {
    out = truth;
    return;
  }
  out.width = truth.width;
  out.height = truth.height;
  if (spec.lateral) {
    out.z.resize(truth.z.size());  // every pixel is written by jitter_row
    out.incidence.resize(truth.incidence.size());
  } else {
    out.z = truth.z;
    out.incidence = truth.incidence;
  }
  const int w = truth.width;
  const std::uint64_t drop = dropout_threshold(spec.dropout);
  // Every stage on a row before the next row: the row stays in cache between stages.
  each_row(out, key, [&](const RowRandom& rng, float* z, float* incidence, int v) {
    if (spec.lateral) jitter_row(truth, rng, v, z, incidence);
    if (spec.axial || drop > 0) axial_dropout_row(rng, w, spec.axial, drop, z, incidence);
    if (spec.quantisation) quantise_row(w, focal_px * spec.baseline, spec.disparity_step, z);
    if (spec.grazing_invalidation) grazing_row(w, spec.grazing_angle, z, incidence);
    if (spec.edge_invalidation) edges_row(truth, v, spec.edge_threshold, z);
  });
}

DepthImage apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key) {
  DepthImage out;
  apply_noise(truth, spec, focal_px, key, out);
  return out;
}

}  // namespace sonomap::sim
