// SPDX-License-Identifier: GPL-3.0-or-later
#include "core/gp.hpp"

#include <cmath>
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
}  // namespace

void SurfaceGp::train(std::vector<Eigen::Vector3f> points, const GpParams& params) {
  validate(params);
  if (points.empty()) throw std::invalid_argument("SurfaceGp::train: no training points");
  params_ = params;
  a_ = kernel_rate(params);
  points_ = std::move(points);
  const int n = static_cast<int>(points_.size());
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
}

GpPrediction SurfaceGp::predict(const Eigen::Vector3d& x, bool with_variance) const {
  GpPrediction out;
  const size_t n = points_.size();
  if (n == 0) return out;
  const bool se = params_.kernel == GpKernel::RevertingSE;
  // Exponents of the kernel terms; every term is scaled by exp(-max exponent).
  // radius[i] holds the squared radius for the SE kernel (it needs no square root).
  thread_local std::vector<double> expo, radius;
  expo.resize(n);
  radius.resize(n);
  double max_expo = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    const double r2 = (x - points_[i].cast<double>()).squaredNorm();
    radius[i] = se ? r2 : std::sqrt(r2);
    expo[i] = se ? -0.5 * a_ * r2 : -a_ * radius[i];
    max_expo = std::max(max_expo, expo[i]);
  }
  double s = 0.0;
  Eigen::Vector3d g = Eigen::Vector3d::Zero();  // grad f, same scale as s
  for (size_t i = 0; i < n; ++i) {
    const double e = std::exp(expo[i] - max_expo);
    const Eigen::Vector3d diff = x - points_[i].cast<double>();
    if (se) {
      s += alpha_[i] * e;
      g += alpha_[i] * (-a_) * e * diff;
    } else {
      s += alpha_[i] * (1.0 + a_ * radius[i]) * e;
      g += alpha_[i] * (-a_ * a_) * e * diff;
    }
  }
  if (!std::isfinite(s)) return out;
  if (!(s > 0.0)) {
    // Far from the points the nearest one dominates, and a negative weight there makes the
    // mean negative: no log. The distance to the nearest training point stands in (an upper
    // bound of the distance to the patch), with the capped variance. Skipping such points
    // would keep free-space carving from ever reaching a moved object.
    size_t nearest = 0;
    for (size_t i = 1; i < n; ++i)
      if (radius[i] < radius[nearest]) nearest = i;
    out.distance = se ? std::sqrt(radius[nearest]) : radius[nearest];
    if (out.distance > 0.0) out.gradient = (x - points_[nearest].cast<double>()) / out.distance;
    out.variance = params_.variance_cap;
    out.valid = true;
    return out;
  }
  const double log_f = max_expo + std::log(s);
  out.distance = se ? std::sqrt(2.0 * std::abs(log_f) / a_) : std::abs(log_f) / a_;
  const double gn = g.norm();
  if (gn > 0.0 && std::isfinite(gn)) out.gradient = -g / gn;
  out.valid = std::isfinite(out.distance);
  if (with_variance && out.valid) {
    Eigen::VectorXd kstar(n);
    for (size_t i = 0; i < n; ++i)
      kstar[i] = se ? std::exp(expo[i]) : (1.0 + a_ * radius[i]) * std::exp(expo[i]);
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
