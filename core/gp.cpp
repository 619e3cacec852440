// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/gp.hpp"

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

// Prediction runs over the training points four at a time in GCC/Clang vector types: plain
// IEEE float operations, lane by lane, so the result has the same bits whatever SIMD width the
// compiler picks (the baseline target's SSE2 register holds all four) and with any C library. Sums are kept per lane
// and added up in a fixed order at the end.
constexpr size_t kLanes = 4;
using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = int32_t __attribute__((vector_size(kLanes * sizeof(int32_t))));

Floats load(const float* p) {
  Floats v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// e^x for x <= 0 (Cephes' expf polynomial, relative error about 2e-7). Below -87 it gives
// e^-87 (1.6e-38): kernel terms that small vanish next to the largest, which is 1.
Floats exp_nonpositive(Floats x) {
  const Floats floor_x = Floats{} - 87.0f;
  x = x < floor_x ? floor_x : x;
  const Floats round = Floats{} + 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  const Floats n = (x * 1.44269504088896341f + round) - round;
  const Floats r = (x - n * 0.693359375f) - n * -2.12194440e-4f;  // ln 2 in two parts
  Floats p = Floats{} + 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  const Ints bits = (__builtin_convertvector(n, Ints) + 127) << 23;  // 2^n
  return p * (Floats)bits;  // a vector cast keeps the bits
}

float lane_max(Floats v) {
  float m = v[0];
  for (size_t j = 1; j < kLanes; ++j) m = v[j] > m ? v[j] : m;
  return m;
}

double lane_sum(Floats v) {
  double s = 0.0;
  for (size_t j = 0; j < kLanes; ++j) s += v[j];
  return s;
}
}  // namespace

void SurfaceGp::train(std::vector<Eigen::Vector3f> points, const GpParams& params) {
  validate(params);
  if (points.empty()) throw std::invalid_argument("SurfaceGp::train: no training points");
  params_ = params;
  a_ = kernel_rate(params);
  points_ = std::move(points);
  const int n = static_cast<int>(points_.size());
  anchor_ = points_[0].cast<double>();
  // Padded to whole vectors with points 1 km away and no weight: their terms are zero.
  const size_t padded = (points_.size() + kLanes - 1) / kLanes * kLanes;
  xs_.assign(padded, 1000.0f);
  ys_.assign(padded, 0.0f);
  zs_.assign(padded, 0.0f);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = points_[i].cast<double>() - anchor_;
    xs_[i] = static_cast<float>(d.x());
    ys_[i] = static_cast<float>(d.y());
    zs_[i] = static_cast<float>(d.z());
  }
  Eigen::MatrixXd k(n, n);
  for (int i = 0; i < n; ++i) {
    k(i, i) = 1.0 + params_.noise;
    for (int j = 0; j < i; ++j) {
      const double r2 = (points_[i] - points_[j]).cast<double>().squaredNorm();
      const double v = params_.kernel == GpKernel::RevertingSE
                           ? std::exp(-0.5 * a_ * r2)
                           : (1.0 + a_ * std::sqrt(r2)) * std::exp(-a_ * std::sqrt(r2));
      k(i, j) = v;
      k(j, i) = v;
    }
  }
  llt_.compute(k);
  alpha_ = llt_.solve(Eigen::VectorXd::Ones(n));
  alpha_lanes_.assign(padded, 0.0f);
  for (int i = 0; i < n; ++i) alpha_lanes_[i] = static_cast<float>(alpha_[i]);
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
  const float qx = static_cast<float>(rel.x()), qy = static_cast<float>(rel.y()), qz = static_cast<float>(rel.z());
  const float rate = static_cast<float>(a_);
  const size_t padded = xs_.size();
  // Exponents of the kernel terms; every term is scaled by exp(-max exponent).
  // radius holds the squared radius for the SE kernel (it needs no square root).
  thread_local std::vector<float> expo, radius;
  expo.resize(padded);
  radius.resize(padded);
  Floats top = Floats{} - std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < padded; i += kLanes) {
    const Floats dx = qx - load(&xs_[i]), dy = qy - load(&ys_[i]), dz = qz - load(&zs_[i]);
    Floats r = dx * dx + dy * dy + dz * dz;
    if (!se)
      for (size_t j = 0; j < kLanes; ++j) r[j] = std::sqrt(r[j]);
    const Floats e = se ? -0.5f * rate * r : -rate * r;
    std::memcpy(&radius[i], &r, sizeof r);
    std::memcpy(&expo[i], &e, sizeof e);
    top = e > top ? e : top;
  }
  const float max_expo = lane_max(top);
  Floats f = {};
  [[maybe_unused]] Floats gx = {}, gy = {}, gz = {};  // f and grad f / (-rate), per lane
  for (size_t i = 0; i < padded; i += kLanes) {
    Floats w = load(&alpha_lanes_[i]) * exp_nonpositive(load(&expo[i]) - max_expo);
    if constexpr (kGradient) {
      gx += w * (qx - load(&xs_[i]));
      gy += w * (qy - load(&ys_[i]));
      gz += w * (qz - load(&zs_[i]));
    }
    f += se ? w : w * (1.0f + rate * load(&radius[i]));
  }
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
  out.distance = se ? std::sqrt(2.0 * std::abs(log_f) / a_) : std::abs(log_f) / a_;
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
    const Eigen::VectorXd v = llt_.matrixL().solve(kstar);
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
