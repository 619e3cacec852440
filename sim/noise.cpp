// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/noise.hpp"

#include "core/vector_isa.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace sonomap::sim {

namespace {

// Keeps the grazing terms finite when a surface is seen exactly edge-on.
constexpr double kMaxTheta = M_PI / 2 - 1e-3;

// std::min and std::clamp on values, with the same comparisons: the standard ones return
// references, which keeps GCC from vectorising the loops.
SONOMAP_VECTOR_LOOP double min_of(double a, double b) { return b < a ? b : a; }
SONOMAP_VECTOR_LOOP double clamp_of(double x, double lo, double hi) { return x < lo ? lo : hi < x ? hi : x; }
SONOMAP_VECTOR_LOOP int clamp_of(int x, int lo, int hi) { return x < lo ? lo : hi < x ? hi : x; }

// axial_sigma and lateral_sigma_px for the per-pixel loops: a library's exported functions are
// not inlined (they could be interposed), these are. Branch-free: base + 0.0 is base exactly,
// so this is the same number as adding the grazing term only beyond 60 degrees.
SONOMAP_VECTOR_LOOP double axial_sigma_of(double z, double theta) {
  const double t = min_of(theta, kMaxTheta);
  const double grazing = 0.0001 / std::sqrt(z) * t * t / ((M_PI / 2 - t) * (M_PI / 2 - t));
  return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) + (theta > M_PI / 3 ? grazing : 0.0);
}

SONOMAP_VECTOR_LOOP double lateral_sigma_px_of(double theta) {
  const double t = min_of(theta, kMaxTheta);
  return 0.8 + 0.035 * t / (M_PI / 2 - t);
}

// Round half up (floor(x + 0.5)) without a libm call; offsets are small, so the int
// conversion cannot overflow after the clamp.
SONOMAP_VECTOR_LOOP int nearest_int(double x) {
  const double y = clamp_of(x, -1e6, 1e6) + 0.5;
  const int i = static_cast<int>(y);  // truncates towards zero
  return i - (y < i);
}

RandomStream row_stream(const NoiseKey& key, StreamPurpose purpose, int row) {
  return RandomStream({key.seed, key.sensor, key.frame, static_cast<std::uint64_t>(purpose),
                       static_cast<std::uint64_t>(row)});
}

// Dropout with probability p: the high half of the pixel's axial word below p 2^32.
std::uint64_t dropout_threshold(double p) { return static_cast<std::uint64_t>(std::clamp(p, 0.0, 1.0) * 0x1.0p32); }

// What one pass over the rows does: the stages that are on, in the documented order.
struct Pass {
  NoiseKey key;
  const DepthImage* jitter_source = nullptr;  // lateral jitter from this image; null: off
  bool axial = false;
  std::uint64_t drop = 0;  // dropout below this threshold on the axial word's high half; 0: off
  bool quantise = false;
  double fb = 0.0, step = 0.0;  // focal length x baseline, disparity step
  bool grazing = false;
  double grazing_angle = 0.0;
  const DepthImage* edge_reference = nullptr;  // edge invalidation against this image; null: off
  double edge_threshold = 0.0;
};

// One thread's row buffers: a stream's words split in halves, normals and their slow flags.
// Every pixel u takes word u of each stream (SplitMix64 is a counter), so a pixel's noise
// depends on its key and position only: the same whether the stages run one by one or fused,
// in any order, on any thread, vectorised or not.
struct RowScratch {
  explicit RowScratch(int width)
      : low(width), high(width), slow_first(width), slow_second(width), first(width), second(width) {}
  std::vector<std::uint32_t> low, high, slow_first, slow_second;
  std::vector<float> first, second;
};

// The stages on one image row: z and incidence point at the row's first pixel of the image
// being changed. Each is a short loop of its own (each vectorises on its own; the rare slow
// normals are patched in between, pixel by pixel).

// The row of `in` under lateral jitter, into z and incidence (which do not alias `in`):
// each pixel takes the depth and incidence of the pixel at its rounded normal offset.
SONOMAP_VECTOR_LOOP void jitter_gather(const DepthImage& in, int v, const float* __restrict du,
                                       const float* __restrict dv, float* __restrict z, float* __restrict incidence) {
  const int w = in.width, h = in.height;
  const float* __restrict in_z = in.z.data();
  const float* __restrict in_incidence = in.incidence.data();
  const float* __restrict row_incidence = in_incidence + static_cast<std::size_t>(v) * w;
  for (int u = 0; u < w; ++u) {
    const double sigma = lateral_sigma_px_of(row_incidence[u]);
    const int su = clamp_of(u + nearest_int(sigma * du[u]), 0, w - 1);
    const int sv = clamp_of(v + nearest_int(sigma * dv[u]), 0, h - 1);
    const int source = sv * w + su;  // images have fewer than INT_MAX pixels (run_pass)
    z[u] = in_z[source];
    incidence[u] = in_incidence[source];
  }
}

// Jitter word u: its low half gives the offset in u, its high half the offset in v (slow
// draws keyed 2u and 2u + 1).
SONOMAP_VECTOR_LOOP void jitter_row(const DepthImage& in, const RandomStream& rng, int v, RowScratch& s, float* z,
                                    float* incidence) {
  const int w = in.width;
  rng.words(w, s.low.data(), s.high.data());
  rng.normal32_fast(s.low.data(), w, s.first.data(), s.slow_first.data());
  rng.normal32_fast(s.high.data(), w, s.second.data(), s.slow_second.data());
  for (int u = 0; u < w; ++u) {
    const std::uint64_t slow = 2 * static_cast<std::uint64_t>(u);
    if (s.slow_first[u]) s.first[u] = rng.normal32(s.low[u], slow);
    if (s.slow_second[u]) s.second[u] = rng.normal32(s.high[u], slow + 1);
  }
  jitter_gather(in, v, s.first.data(), s.second.data(), z, incidence);
}

// z + n axial_sigma(z, theta); a result <= 0 becomes no return.
SONOMAP_VECTOR_LOOP float axial_noisy(float z, float incidence, float n) {
  const double noisy = z + axial_sigma_of(z, incidence) * n;
  return noisy > 0.0 ? static_cast<float>(noisy) : 0.0f;
}

// Axial noise (if `axial`) and dropout below `threshold` from the same words: word u's low half
// gives the axial normal (slow draws keyed u), its high half the dropout draw. Pixels with no
// return, and dropped pixels, never take a slow draw.
SONOMAP_VECTOR_LOOP void axial_dropout_row(const RandomStream& rng, int w, bool axial, std::uint64_t threshold,
                                           RowScratch& s, float* __restrict z, const float* __restrict incidence) {
  std::uint32_t* low = s.low.data();
  std::uint32_t* high = s.high.data();
  float* normal = s.first.data();
  std::uint32_t* slow = s.slow_first.data();
  rng.words(w, low, high);
  const bool drop_all = threshold > 0xffffffffu;
  const auto threshold32 = static_cast<std::uint32_t>(drop_all ? 0 : threshold);
  auto kept = [&](int u) { return !drop_all & (high[u] >= threshold32); };
  if (!axial) {
    for (int u = 0; u < w; ++u) z[u] = (z[u] > 0.0f) & !kept(u) ? 0.0f : z[u];
    return;
  }
  rng.normal32_fast(low, w, normal, slow);
  for (int u = 0; u < w; ++u)
    if (slow[u] && z[u] > 0.0f && kept(u)) normal[u] = rng.normal32(low[u], static_cast<std::uint64_t>(u));
  for (int u = 0; u < w; ++u) {
    // Computed for every pixel (branch-free), used where there is a return that is kept.
    const float noisy = axial_noisy(z[u], incidence[u], normal[u]);
    z[u] = z[u] > 0.0f ? (kept(u) ? noisy : 0.0f) : z[u];
  }
}

// Depth measured as a whole number of disparity steps (fb = focal length x baseline).
// Round half up; the step count is positive, so truncation is floor (z = 0 gives 1e9 + 0.5).
SONOMAP_VECTOR_LOOP void quantise_row(int w, double fb, double step, float* __restrict z) {
  for (int u = 0; u < w; ++u) {
    const double depth = z[u];
    // The disparity; > 0 iff the step count is (step > 0). Both tests on doubles: GCC
    // vectorises the selection then.
    const double disparity = static_cast<std::int32_t>(min_of(fb / (depth * step), 1e9) + 0.5) * step;
    const float quantised = static_cast<float>(fb / disparity);
    z[u] = (depth > 0.0) & (disparity > 0.0) ? quantised : 0.0f;
  }
}

SONOMAP_VECTOR_LOOP void grazing_row(int w, double max_angle, float* __restrict z, const float* __restrict incidence) {
  for (int u = 0; u < w; ++u) z[u] = incidence[u] > max_angle ? 0.0f : z[u];
}

// A neighbour n differs from z: no surface there, or more than threshold nearer or farther.
SONOMAP_VECTOR_LOOP bool differs(float n, float z, double threshold) {
  return !(n > 0.0f) | (std::abs(static_cast<double>(n) - z) > threshold);
}

SONOMAP_VECTOR_LOOP void edges_row(const DepthImage& reference, int v, double threshold, float* __restrict z) {
  const int w = reference.width;
  const float* __restrict truth = reference.z.data() + static_cast<std::size_t>(v) * w;
  const float* __restrict above = v > 0 ? truth - w : truth;  // the image's border repeats: no difference
  const float* __restrict below = v + 1 < reference.height ? truth + w : truth;
  auto edge_at = [&](int u, int left, int right) {
    const float z0 = truth[u];
    const bool edge = differs(truth[left], z0, threshold) | differs(truth[right], z0, threshold) |
                      differs(above[u], z0, threshold) | differs(below[u], z0, threshold);
    z[u] = z0 > 0.0f && edge ? 0.0f : z[u];
  };
  edge_at(0, 0, std::min(1, w - 1));
  for (int u = 1; u + 1 < w; ++u) edge_at(u, u - 1, u + 1);  // the interior, without border tests
  if (w > 1) edge_at(w - 1, w - 2, w - 1);
}

// Every stage of the pass on row v of `out`, stage after stage (the row stays in cache).
SONOMAP_VECTOR_LOOP void noise_row(const Pass& pass, RowScratch& s, DepthImage& out, int v) {
  const int w = out.width;
  const std::size_t row = static_cast<std::size_t>(v) * w;
  float* z = out.z.data() + row;
  float* incidence = out.incidence.data() + row;
  if (pass.jitter_source)
    jitter_row(*pass.jitter_source, row_stream(pass.key, StreamPurpose::LateralJitter, v), v, s, z, incidence);
  if (pass.axial || pass.drop > 0)
    axial_dropout_row(row_stream(pass.key, StreamPurpose::AxialNoise, v), w, pass.axial, pass.drop, s, z, incidence);
  if (pass.quantise) quantise_row(w, pass.fb, pass.step, z);
  if (pass.grazing) grazing_row(w, pass.grazing_angle, z, incidence);
  if (pass.edge_reference) edges_row(*pass.edge_reference, v, pass.edge_threshold, z);
}

void row_baseline(const Pass& pass, RowScratch& s, DepthImage& out, int v) { noise_row(pass, s, out, v); }
SONOMAP_AVX2_KERNEL void row_avx2(const Pass& pass, RowScratch& s, DepthImage& out, int v) {
  noise_row(pass, s, out, v);
}
SONOMAP_AVX512_KERNEL void row_avx512(const Pass& pass, RowScratch& s, DepthImage& out, int v) {
  noise_row(pass, s, out, v);
}

// Runs the pass on every row of `out` (sized and filled by the caller), rows over TBB threads.
void run_pass(DepthImage& out, const Pass& pass) {
  if (out.z.size() > static_cast<std::size_t>(INT_MAX))
    throw std::invalid_argument("apply_noise: images of more than INT_MAX pixels are not supported");
  const auto row = kernel_for(vector_isa(), &row_baseline, &row_avx2, &row_avx512);
  tbb::parallel_for(tbb::blocked_range<int>(0, out.height), [&](const tbb::blocked_range<int>& rows) {
    RowScratch scratch(out.width);
    for (int v = rows.begin(); v < rows.end(); ++v) row(pass, scratch, out, v);
  });
}

// A copy of `in` with `pass` applied.
DepthImage changed(DepthImage image, const Pass& pass) {
  run_pass(image, pass);
  return image;
}

}  // namespace

double axial_sigma(double z, double theta) { return axial_sigma_of(z, theta); }

double lateral_sigma_px(double theta) { return lateral_sigma_px_of(theta); }

DepthImage jitter_lateral(const DepthImage& in, const NoiseKey& key) {
  DepthImage out;
  out.width = in.width;
  out.height = in.height;
  out.z.resize(in.z.size());  // every pixel is written by the jitter
  out.incidence.resize(in.incidence.size());
  Pass pass;
  pass.key = key;
  pass.jitter_source = &in;
  run_pass(out, pass);
  return out;
}

DepthImage add_axial_noise(const DepthImage& in, const NoiseKey& key) {
  Pass pass;
  pass.key = key;
  pass.axial = true;
  return changed(in, pass);
}

DepthImage quantise_disparity(const DepthImage& in, double focal_px, double baseline, double step) {
  Pass pass;
  pass.quantise = true;
  pass.fb = focal_px * baseline;
  pass.step = step;
  return changed(in, pass);
}

DepthImage invalidate_grazing(const DepthImage& in, double max_angle) {
  Pass pass;
  pass.grazing = true;
  pass.grazing_angle = max_angle;
  return changed(in, pass);
}

DepthImage invalidate_edges(const DepthImage& in, const DepthImage& reference, double threshold) {
  Pass pass;
  pass.edge_reference = &reference;
  pass.edge_threshold = threshold;
  return changed(in, pass);
}

DepthImage drop_out(const DepthImage& in, double p, const NoiseKey& key) {
  Pass pass;
  pass.key = key;
  pass.drop = dropout_threshold(p);
  return changed(in, pass);
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
    out.z.resize(truth.z.size());  // every pixel is written by the jitter
    out.incidence.resize(truth.incidence.size());
  } else {
    out.z = truth.z;
    out.incidence = truth.incidence;
  }
  Pass pass;
  pass.key = key;
  pass.jitter_source = spec.lateral ? &truth : nullptr;
  pass.axial = spec.axial;
  pass.drop = dropout_threshold(spec.dropout);
  pass.quantise = spec.quantisation;
  pass.fb = focal_px * spec.baseline;
  pass.step = spec.disparity_step;
  pass.grazing = spec.grazing_invalidation;
  pass.grazing_angle = spec.grazing_angle;
  pass.edge_reference = spec.edge_invalidation ? &truth : nullptr;
  pass.edge_threshold = spec.edge_threshold;
  run_pass(out, pass);
}

DepthImage apply_noise(const DepthImage& truth, const NoiseSpec& spec, double focal_px, const NoiseKey& key) {
  DepthImage out;
  apply_noise(truth, spec, focal_px, key, out);
  return out;
}

}  // namespace sonomap::sim
