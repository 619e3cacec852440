// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/gp.hpp"
#include "core/vector_isa.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace sonomap {

void validate(const GpParams& p) {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("GP parameter ") + name +
                                  " must be positive and finite, got " + std::to_string(v));
  };
  positive(p.lambda, "lambda");
  positive(p.noise, "map_noise");
  positive(p.variance_cap, "variance_cap");
  positive(p.variance_on_surface, "variance_on_surface");
}

namespace {
double kernel_rate(const GpParams& p) {
  return p.kernel == GpKernel::RevertingSE ? p.lambda : std::sqrt(3.0 * p.lambda);
}

// Prediction runs over the training points in GCC/Clang vector types: plain IEEE float
// operations, lane by lane, so every term has the same bits whatever the vector width, and
// with any C library. The widest copy the CPU runs (core/vector_isa.hpp: 4 lanes on the
// baseline, 8 with AVX2, 16 with AVX-512) computes the terms; they are summed into four lanes,
// four terms at a time in the points' order, and the four added up in a fixed order at the
// end: the sums are those of the 4-lane baseline, to the bit.
// The wide helpers below return 32- and 64-byte vectors (and take them by reference); they are
// always inlined into kernels built for the instruction set that holds them, so no call
// passes such a vector and GCC's warning that the calling convention differs without AVX
// does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
constexpr size_t kLanes = 4;
constexpr size_t kWidest = 16;  // the training points are padded to a multiple of this
template <size_t L>
struct Lanes {  // (an alias template drops a dependent vector_size)
  typedef float Floats __attribute__((vector_size(L * sizeof(float))));
  typedef int32_t Ints __attribute__((vector_size(L * sizeof(int32_t))));
};
template <size_t L>
using WideFloats = typename Lanes<L>::Floats;
template <size_t L>
using WideInts = typename Lanes<L>::Ints;
using Floats = WideFloats<kLanes>;

template <size_t L>
SONOMAP_VECTOR_LOOP WideFloats<L> load(const float* p) {
  WideFloats<L> v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// e^x for x <= 0 (Cephes' expf polynomial, relative error about 2e-7). Below -87 it gives
// e^-87 (1.6e-38): kernel terms that small vanish next to the largest, which is 1.
template <size_t L>
SONOMAP_VECTOR_LOOP WideFloats<L> exp_nonpositive(const WideFloats<L>& exponent) {
  using W = WideFloats<L>;
  const W floor_x = W{} - 87.0f;
  const W x = exponent < floor_x ? floor_x : exponent;
  const W round = W{} + 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  const W n = (x * 1.44269504088896341f + round) - round;
  const W r = (x - n * 0.693359375f) - n * -2.12194440e-4f;  // ln 2 in two parts
  W p = W{} + 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  const WideInts<L> bits = (__builtin_convertvector(n, WideInts<L>) + 127) << 23;  // 2^n
  return p * (W)bits;  // a vector cast keeps the bits
}

// Adds v's lanes to the four of `sum`, four at a time in order.
template <size_t L>
SONOMAP_VECTOR_LOOP void add_by_fours(Floats& sum, const WideFloats<L>& v) {
  float lanes[L];
  std::memcpy(lanes, &v, sizeof v);
  for (size_t q = 0; q < L; q += kLanes) sum += load<kLanes>(&lanes[q]);
}

double lane_sum(Floats v) {
  double s = 0.0;
  for (size_t j = 0; j < kLanes; ++j) s += v[j];
  return s;
}

// One prediction's input: the training points relative to the anchor, one array per axis,
// their weights (padded to kWidest with points 1 km away and weight 0), and the query. A copy
// of L lanes reads the count rounded up to L: padding terms are +-0 and leave every sum's bits
// as they are, so the narrower copies do no more work than their width needs.
struct KernelInput {
  const float *xs, *ys, *zs, *alpha;
  size_t count;
  float qx, qy, qz, rate;
  bool se;
};

// Its sums: the largest exponent, and f and grad f / (-rate) in four lanes.
struct KernelSums {
  float max_expo;
  Floats f, gx, gy, gz;
};

// Fills expo (the kernel terms' exponents) and radius (the squared radius for the SE kernel,
// which needs no square root) and sums every term scaled by exp(-max exponent).
template <size_t L, bool kGradient>
SONOMAP_VECTOR_LOOP void sum_kernel_terms(const KernelInput& in, float* expo, float* radius, KernelSums& out) {
  using W = WideFloats<L>;
  const size_t end = (in.count + L - 1) / L * L;
  W top = W{} - std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < end; i += L) {
    const W dx = in.qx - load<L>(in.xs + i), dy = in.qy - load<L>(in.ys + i), dz = in.qz - load<L>(in.zs + i);
    W r = dx * dx + dy * dy + dz * dz;
    if (!in.se)
      for (size_t j = 0; j < L; ++j) r[j] = std::sqrt(r[j]);
    const W e = in.se ? -0.5f * in.rate * r : -in.rate * r;
    std::memcpy(radius + i, &r, sizeof r);
    std::memcpy(expo + i, &e, sizeof e);
    top = e > top ? e : top;
  }
  float max_expo = top[0];
  for (size_t j = 1; j < L; ++j) max_expo = top[j] > max_expo ? top[j] : max_expo;
  out.max_expo = max_expo;
  out.f = out.gx = out.gy = out.gz = Floats{};
  for (size_t i = 0; i < end; i += L) {
    const W w = load<L>(in.alpha + i) * exp_nonpositive<L>(load<L>(expo + i) - max_expo);
    if constexpr (kGradient) {
      add_by_fours<L>(out.gx, w * (in.qx - load<L>(in.xs + i)));
      add_by_fours<L>(out.gy, w * (in.qy - load<L>(in.ys + i)));
      add_by_fours<L>(out.gz, w * (in.qz - load<L>(in.zs + i)));
    }
    add_by_fours<L>(out.f, in.se ? w : w * (1.0f + in.rate * load<L>(radius + i)));
  }
}

template <bool kGradient>
void sum_kernel_terms_baseline(const KernelInput& in, float* expo, float* radius, KernelSums& out) {
  sum_kernel_terms<kLanes, kGradient>(in, expo, radius, out);
}
template <bool kGradient>
SONOMAP_AVX2_KERNEL void sum_kernel_terms_avx2(const KernelInput& in, float* expo, float* radius, KernelSums& out) {
  sum_kernel_terms<8, kGradient>(in, expo, radius, out);
}
template <bool kGradient>
SONOMAP_AVX512_KERNEL void sum_kernel_terms_avx512(const KernelInput& in, float* expo, float* radius,
                                                   KernelSums& out) {
  sum_kernel_terms<16, kGradient>(in, expo, radius, out);
}

// The kernel matrix K0 + noise I of the points at kernel rate a (only its lower triangle is
// read by the Cholesky factorisation; both are filled).
void fill_kernel_matrix(const std::vector<Eigen::Vector3f>& points, const GpParams& params, double a,
                        Eigen::Ref<Eigen::MatrixXd> k) {
  const int n = static_cast<int>(points.size());
  for (int i = 0; i < n; ++i) {
    k(i, i) = 1.0 + params.noise;
    for (int j = 0; j < i; ++j) {
      const double r2 = (points[i] - points[j]).cast<double>().squaredNorm();
      const double v = params.kernel == GpKernel::RevertingSE
                           ? std::exp(-0.5 * a * r2)
                           : (1.0 + a * std::sqrt(r2)) * std::exp(-a * std::sqrt(r2));
      k(i, j) = v;
      k(j, i) = v;
    }
  }
}
}  // namespace

void SurfaceGp::train(std::vector<Eigen::Vector3f> points, const GpParams& params) {
  validate(params);
  if (points.empty()) throw std::invalid_argument("SurfaceGp::train: no training points");
  params_ = params;
  a_ = kernel_rate(params);
  points_ = std::move(points);
  const size_t n = points_.size();
  // Padded to whole vectors with points 1 km away and no weight: their terms are zero.
  padded_ = (n + kWidest - 1) / kWidest * kWidest;
  store_.assign(4 * padded_ + n + row_start(n), 0.0f);
  anchor_ = points_[0].cast<double>();
  float* xs = store_.data();
  std::fill(xs, xs + padded_, 1000.0f);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = points_[i].cast<double>() - anchor_;
    xs[i] = static_cast<float>(d.x());
    xs[padded_ + i] = static_cast<float>(d.y());
    xs[2 * padded_ + i] = static_cast<float>(d.z());
  }
  // The kernel matrix and the weights in scratch kept by the thread (a frame trains hundreds of
  // GPs): K alpha = 1, K factored in place.
  thread_local std::vector<double> scratch;
  scratch.resize(n * n + n);
  const Eigen::Index size = static_cast<Eigen::Index>(n);
  Eigen::Map<Eigen::MatrixXd> k(scratch.data(), size, size);
  fill_kernel_matrix(points_, params_, a_, k);
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(k);
  Eigen::Map<Eigen::VectorXd> alpha(scratch.data() + n * n, size);
  alpha.setOnes();
  llt.solveInPlace(alpha);
  keep_solution(alpha, llt.matrixLLT());
}

void SurfaceGp::keep_solution(const Eigen::Ref<const Eigen::VectorXd>& alpha,
                              const Eigen::Ref<const Eigen::MatrixXd>& factor) {
  const size_t n = points_.size();
  float* alpha_lanes = store_.data() + 3 * padded_;
  for (size_t i = 0; i < n; ++i) alpha_lanes[i] = static_cast<float>(alpha[i]);
  // A mean of 0 or below has no log: predict() then takes the distance to the nearest point,
  // here the point itself.
  float* distances = store_.data() + 4 * padded_;
  for (size_t i = 0; i < n; ++i) {
    const double f = 1.0 - params_.noise * alpha[i];
    distances[i] = f > 0.0 ? static_cast<float>(distance_of(std::log(f))) : 0.0f;
  }
  // The Cholesky factor (L in the lower triangle of `factor`) is kept for the variance only, in
  // float and packed: a quarter of the double matrix (a mapped room's global GPs held 23 MB of
  // factors in double).
  float* lower = distances + n;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j <= i; ++j) lower[row_start(i) + j] = static_cast<float>(factor(i, j));
}

size_t SurfaceGp::memory_bytes() const {
  return points_.capacity() * sizeof(Eigen::Vector3f) + store_.capacity() * sizeof(float);
}

double SurfaceGp::distance_of(double log_f) const {
  return params_.kernel == GpKernel::RevertingSE ? std::sqrt(2.0 * std::abs(log_f) / a_) : std::abs(log_f) / a_;
}

GpPrediction SurfaceGp::predict(const Eigen::Vector3d& x, bool with_variance, bool with_gradient) const {
  return with_gradient ? predict_as<true>(x, with_variance) : predict_as<false>(x, with_variance);
}

template <bool kGradient>
GpPrediction SurfaceGp::predict_as(const Eigen::Vector3d& x, bool with_variance) const {
  GpPrediction out;
  const size_t n = points_.size();
  if (n == 0) return out;
  const bool se = params_.kernel == GpKernel::RevertingSE;
  const Eigen::Vector3d rel = x - anchor_;
  if (!rel.allFinite()) return out;
  const KernelInput in{lane(0), lane(1), lane(2), lane(3), n,
                       static_cast<float>(rel.x()), static_cast<float>(rel.y()), static_cast<float>(rel.z()),
                       static_cast<float>(a_), se};
  // Scratch on the stack for the usual sizes (a local GP has at most about 100 points).
  constexpr size_t kOnStack = 256;
  float expo_stack[kOnStack], radius_stack[kOnStack];
  float* expo = expo_stack;
  float* radius = radius_stack;
  if (padded_ > kOnStack) {
    thread_local std::vector<float> expo_heap, radius_heap;  // (a guard per use: here only)
    expo_heap.resize(padded_);
    radius_heap.resize(padded_);
    expo = expo_heap.data();
    radius = radius_heap.data();
  }
  const auto sum_terms = kernel_for(vector_isa(), &sum_kernel_terms_baseline<kGradient>,
                                    &sum_kernel_terms_avx2<kGradient>, &sum_kernel_terms_avx512<kGradient>);
  KernelSums sums;
  sum_terms(in, expo, radius, sums);
  const float max_expo = sums.max_expo;
  const Floats f = sums.f;
  [[maybe_unused]] const Floats gx = sums.gx, gy = sums.gy, gz = sums.gz;
  const double s = lane_sum(f);
  if (!std::isfinite(s)) return out;
  if (!(s > 0.0)) {
    // Far from the points the nearest one dominates, and a negative weight there makes the
    // mean negative: no log. The distance to the nearest training point stands in (an upper
    // bound of the distance to the patch), with the capped variance. Skipping such points
    // would keep free-space carving from ever reaching a moved object.
    size_t nearest = 0;
    for (size_t i = 1; i < n; ++i)
      if (radius[i] < radius[nearest]) nearest = i;
    out.distance = se ? std::sqrt(static_cast<double>(radius[nearest])) : static_cast<double>(radius[nearest]);
    if (kGradient && out.distance > 0.0) out.gradient = (x - points_[nearest].cast<double>()) / out.distance;
    out.variance = params_.variance_cap;
    out.valid = true;
    return out;
  }
  const double log_f = static_cast<double>(max_expo) + std::log(s);
  out.distance = distance_of(log_f);
  if constexpr (kGradient) {
    const Eigen::Vector3d g = -(se ? a_ : a_ * a_) * Eigen::Vector3d(lane_sum(gx), lane_sum(gy), lane_sum(gz));
    const double gn = g.norm();
    if (gn > 0.0 && std::isfinite(gn)) out.gradient = -g / gn;
  }
  out.valid = std::isfinite(out.distance);
  if (with_variance && out.valid) {
    Eigen::VectorXd kstar(n);
    for (size_t i = 0; i < n; ++i)
      kstar[i] = se ? std::exp(double(expo[i])) : (1.0 + a_ * radius[i]) * std::exp(double(expo[i]));
    // v = L^-1 k* by forward substitution, summed in double; var f = 1 - |v|^2.
    Eigen::VectorXd v(n);
    for (size_t i = 0; i < n; ++i) {
      const float* row = lower() + row_start(i);
      double s = kstar[i];
      for (size_t j = 0; j < i; ++j) s -= static_cast<double>(row[j]) * v[j];
      v[i] = s / static_cast<double>(row[i]);
    }
    const double var_f = std::max(0.0, 1.0 - v.squaredNorm());
    const double f = std::exp(log_f);
    // First-order propagation through d(f): dd/df = -1/(a f d) (SE) or -1/(a f) (Matern).
    const double dd_df = se ? 1.0 / (a_ * f * out.distance) : 1.0 / (a_ * f);
    double var = var_f * dd_df * dd_df;
    if (!std::isfinite(var)) var = params_.variance_on_surface;
    out.variance = std::min(var, params_.variance_cap);
  }
  return out;
}

}  // namespace sonomap
