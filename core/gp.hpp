// SPDX-License-Identifier: GPL-3.0-or-later
// One small Gaussian process over surface points, the building block of VDB-GPDF (vdb_gpdf.hpp):
// a latent occupancy-like field f (targets all 1, zero mean, prior variance 1) turned into a
// distance d. Used for the local GPs (one per local leaf) and the global GPs (one per global
// leaf, trained on marching-cubes zero crossings).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace sonomap {

enum class GpKernel {
  RevertingSE,     // k = exp(-a r^2 / 2), a = lambda;    d = sqrt(2 |ln f| / a)   (default)
  LogGpisMatern32  // k = (1 + a r) e^(-a r), a = sqrt(3 lambda);  d = |ln f| / a
};

struct GpParams {
  GpKernel kernel = GpKernel::RevertingSE;
  double lambda = 900.0;               // 1 / lengthscale^2 (l = 3.33 cm)
  double noise = 0.01;                 // added to the diagonal of K
  double variance_cap = 0.1;           // distance variance ceiling
  double variance_on_surface = 0.001;  // where the propagated variance is undefined (d = 0)
};

struct GpPrediction {
  bool valid = false;  // false only for non-finite input
  double distance = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // unit, away from the surface (0 if flat)
  double variance = 0.0;
};

class SurfaceGp {
 public:
  SurfaceGp() = default;
  // Trains on the given points. Throws std::invalid_argument if points is empty or the
  // parameters are out of range.
  void train(std::vector<Eigen::Vector3f> points, const GpParams& params);
  bool trained() const { return !points_.empty(); }
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  // Number of training points (size of the kernel matrix).
  size_t size() const { return points_.size(); }
  // Heap bytes held (training points, their SIMD copies and weights, the Cholesky factor).
  size_t memory_bytes() const;

  // Distance, gradient (grad d = -grad f / |grad f|) and, if asked, variance at x.
  // f is evaluated relative to its largest kernel term, so far from the points the distance
  // stays finite instead of underflowing to "f = 0". Without with_gradient the gradient is
  // left zero and not computed (the mapper's per-frame queries need only distances).
  GpPrediction predict(const Eigen::Vector3d& x, bool with_variance, bool with_gradient = true) const;
  // The distance predict() gives at training point i (points()[i]), from the training solve
  // itself: K alpha = 1 with K = K0 + noise I, so the mean there, K0 alpha, is 1 - noise alpha_i.
  // One look-up in place of predict's sum over every point (VDB-GPDF asks it at each of a
  // frame's training points, about half of its GP queries). Precondition: i < size().
  double distance_at_point(size_t i) const { return point_distances()[i]; }

 private:
  GpParams params_;
  double a_ = 0.0;  // kernel rate (see GpKernel)
  std::vector<Eigen::Vector3f> points_;
  // What prediction reads, in one allocation (a frame trains hundreds of GPs, and each array
  // of its own was an allocation more per GP):
  //  - the points again, relative to the first one, one array per axis, and their weights
  //    alpha, each padded_ long: prediction runs over them in float SIMD lanes (a frame asks
  //    the local GPs about 30 thousand times at 5 cm);
  //  - distance_at_point's distances (size() of them);
  //  - the Cholesky factor L of the kernel matrix (K = L L^T), row i's i + 1 entries from
  //    row_start(i): what the variance needs.
  Eigen::Vector3d anchor_ = Eigen::Vector3d::Zero();
  size_t padded_ = 0;
  std::vector<float> store_;
  const float* lane(size_t k) const { return store_.data() + k * padded_; }  // x, y, z, alpha
  const float* point_distances() const { return lane(4); }
  const float* lower() const { return point_distances() + points_.size(); }
  // Keeps what prediction needs of the solve: the weights alpha, each point's distance and
  // the Cholesky factor L (the lower triangle of `factor`).
  void keep_solution(const Eigen::Ref<const Eigen::VectorXd>& alpha, const Eigen::Ref<const Eigen::MatrixXd>& factor);
  template <bool kGradient>
  GpPrediction predict_as(const Eigen::Vector3d& x, bool with_variance) const;
  // The distance of a mean f = exp(log_f) (log-GPIS: f = exp(-a d) or exp(-a d^2 / 2)).
  double distance_of(double log_f) const;
  static size_t row_start(size_t i) { return i * (i + 1) / 2; }
};

void validate(const GpParams& params);

}  // namespace sonomap
