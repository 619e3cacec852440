// SPDX-License-Identifier: GPL-3.0-or-later
// The local surface GP (core/gp.hpp) as a distance sensor: trained on points of a plane, it
// reads the height above the plane; and its SIMD float prediction agrees with the textbook
// formula evaluated here in double precision (an independent path: Eigen's own solve).
#include "core/gp.hpp"
#include "tests/vector_isas.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

using namespace sonomap;

namespace {

// A 16 cm patch of the plane z = 1.2, points 4 cm apart (a local leaf's training points).
std::vector<Eigen::Vector3f> plane_patch() {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) points.emplace_back(3.0f + 0.04f * i, -1.0f + 0.04f * j, 1.2f);
  return points;
}

// The GP written out in double for the given kernel: f = k*^T (K + noise I)^-1 1 and, with prior
// variance 1, var f = 1 - k*^T (K + noise I)^-1 k*.
struct ReferenceGp {
  bool se;
  double a;  // kernel rate
  double f, var_f;
  double distance() const { return se ? std::sqrt(2.0 * std::abs(std::log(f)) / a) : std::abs(std::log(f)) / a; }
};
ReferenceGp reference_gp(const std::vector<Eigen::Vector3f>& points, const GpParams& p, const Eigen::Vector3d& x) {
  const bool se = p.kernel == GpKernel::RevertingSE;
  const double a = se ? p.lambda : std::sqrt(3.0 * p.lambda);
  auto k = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    const double r = (u - v).norm();
    return se ? std::exp(-0.5 * a * r * r) : (1.0 + a * r) * std::exp(-a * r);
  };
  const int n = static_cast<int>(points.size());
  Eigen::MatrixXd kk(n, n);
  Eigen::VectorXd ks(n);
  for (int i = 0; i < n; ++i) {
    ks[i] = k(x, points[i].cast<double>());
    for (int j = 0; j < n; ++j) kk(i, j) = k(points[i].cast<double>(), points[j].cast<double>()) + (i == j ? p.noise : 0.0);
  }
  const Eigen::LDLT<Eigen::MatrixXd> solver(kk);
  return {se, a, ks.dot(solver.solve(Eigen::VectorXd::Ones(n))), 1.0 - ks.dot(solver.solve(ks))};
}

double reference_distance(const std::vector<Eigen::Vector3f>& points, const GpParams& p, const Eigen::Vector3d& x) {
  return reference_gp(points, p, x).distance();
}

// The distance variance: var f through d(f) to first order, dd/df = 1 / (a f d) (SE) or
// 1 / (a f) (Matern), capped as the GP caps it.
double reference_variance(const std::vector<Eigen::Vector3f>& points, const GpParams& p, const Eigen::Vector3d& x) {
  const ReferenceGp gp = reference_gp(points, p, x);
  const double dd_df = gp.se ? 1.0 / (gp.a * gp.f * gp.distance()) : 1.0 / (gp.a * gp.f);
  return std::min(gp.var_f * dd_df * dd_df, p.variance_cap);
}

// Trains a GP of each kernel on the plane patch and calls check(gp, params, x) at each query.
template <typename Check>
void on_plane_patch(std::initializer_list<Eigen::Vector3d> queries, Check&& check) {
  for (GpKernel kernel : {GpKernel::RevertingSE, GpKernel::LogGpisMatern32}) {
    GpParams params;
    params.kernel = kernel;
    SurfaceGp gp;
    gp.train(plane_patch(), params);
    for (const Eigen::Vector3d& x : queries) check(gp, params, x);
  }
}

}  // namespace

TEST_CASE("GP: the distance variance matches the formula in double within 0.01 percent", "[gp]") {
  int below_cap = 0;
  on_plane_patch({Eigen::Vector3d(3.05, -0.95, 1.21), Eigen::Vector3d(3.11, -0.9, 1.23), Eigen::Vector3d(3.02, -0.97, 1.25),
                  Eigen::Vector3d(3.08, -0.92, 1.28), Eigen::Vector3d(2.95, -1.05, 1.2)},
                 [&](const SurfaceGp& gp, const GpParams& params, const Eigen::Vector3d& x) {
                   const GpPrediction p = gp.predict(x, true);
                   REQUIRE(p.valid);
                   const double expected = reference_variance(plane_patch(), params, x);
                   below_cap += expected < params.variance_cap;
                   CHECK(p.variance == Approx(expected).epsilon(1e-4));
                 });
  CHECK(below_cap >= 4);  // not only the cap compared (two kernels)
}

TEST_CASE("GP: over a patch of a plane, a point d above its middle reads d (d up to 6 cm)", "[gp]") {
  SurfaceGp gp;
  gp.train(plane_patch(), GpParams{});
  for (double d : {0.0, 0.01, 0.02, 0.04, 0.06}) {
    const GpPrediction p = gp.predict(Eigen::Vector3d(3.08, -0.92, 1.2 + d), false);
    REQUIRE(p.valid);
    CHECK(p.distance == Approx(d).margin(0.005));
    if (d > 0.0) CHECK(p.gradient.z() > 0.99);  // straight away from the plane
  }
}

TEST_CASE("GP: the float SIMD prediction matches the formula in double within 0.1 mm", "[gp]") {
  // Above, below, beside and past the patch's corner, near and up to 15 cm away.
  on_plane_patch({Eigen::Vector3d(3.05, -0.95, 1.23), Eigen::Vector3d(3.11, -0.9, 1.1), Eigen::Vector3d(2.95, -1.05, 1.2),
                  Eigen::Vector3d(3.2, -0.8, 1.3), Eigen::Vector3d(3.08, -0.92, 1.35)},
                 [](const SurfaceGp& gp, const GpParams& params, const Eigen::Vector3d& x) {
                   const GpPrediction p = gp.predict(x, false);
                   REQUIRE(p.valid);
                   CHECK(p.distance == Approx(reference_distance(plane_patch(), params, x)).margin(1e-4));
                 });
}

TEST_CASE("GP: a point with 1, 3 and 5 training points (not whole SIMD vectors) reads its distance", "[gp]") {
  for (size_t n : {1u, 3u, 5u}) {
    std::vector<Eigen::Vector3f> points;
    for (size_t i = 0; i < n; ++i) points.emplace_back(0.02f * i, 0.0f, 0.0f);
    SurfaceGp gp;
    gp.train(points, GpParams{});
    const Eigen::Vector3d x(0.0, 0.0, 0.03);
    CHECK(gp.predict(x, false).distance == Approx(reference_distance(points, GpParams{}, x)).margin(1e-4));
  }
}

TEST_CASE("GP: at its own training points, the distance from the training solve is the formula's in double "
          "within 1 micrometre",
          "[gp]") {
  // A bumpy patch (heights 1.2 +- 6 mm), so that the fit misses its points by a measurable distance.
  std::vector<Eigen::Vector3f> bumpy = plane_patch();
  for (size_t i = 0; i < bumpy.size(); ++i) bumpy[i].z() += 0.006f * static_cast<float>(std::sin(1.7 * i));
  for (GpKernel kernel : {GpKernel::RevertingSE, GpKernel::LogGpisMatern32}) {
    GpParams params;
    params.kernel = kernel;
    SurfaceGp gp;
    gp.train(bumpy, params);
    double largest = 0.0;
    for (size_t i = 0; i < bumpy.size(); ++i) {
      const Eigen::Vector3d x = bumpy[i].cast<double>();
      const double expected = reference_distance(bumpy, params, x);
      largest = std::max(largest, expected);
      CHECK(gp.distance_at_point(i) == Approx(expected).margin(1e-6));
      CHECK(gp.distance_at_point(i) == Approx(gp.predict(x, false).distance).margin(1e-4));  // the query path's
    }
    CHECK(largest > 1e-4);  // not only zeros compared
  }
}

TEST_CASE("GP: every instruction set's copy predicts the same bits as the baseline's", "[gp]") {
  // 1 to 40 points of a curved patch (up to three 16-lane vectors, most of them part full), a
  // query above it, one beside it and one 30 cm away, for both kernels, with gradient and
  // variance: the wide copies sum their terms in the baseline's order.
  for (GpKernel kernel : {GpKernel::RevertingSE, GpKernel::LogGpisMatern32}) {
    GpParams params;
    params.kernel = kernel;
    for (size_t n : {1u, 4u, 15u, 16u, 17u, 33u, 40u}) {
      std::vector<Eigen::Vector3f> points;
      for (size_t i = 0; i < n; ++i) {
        const float u = 0.023f * static_cast<float>(i % 7), v = 0.031f * static_cast<float>(i / 7);
        points.emplace_back(2.0f + u, -0.5f + v, 0.8f + 0.3f * u * v);
      }
      SurfaceGp gp;
      gp.train(points, params);
      for (const Eigen::Vector3d& x : {Eigen::Vector3d(2.05, -0.45, 0.83), Eigen::Vector3d(1.9, -0.5, 0.8),
                                      Eigen::Vector3d(2.3, -0.2, 1.1)}) {
        auto predicted = [&](VectorIsa isa) {
          const ScopedVectorIsa code(isa);
          return gp.predict(x, true, true);
        };
        const GpPrediction baseline = predicted(VectorIsa::Baseline);
        REQUIRE(baseline.valid);
        for (VectorIsa isa : vector_isas_beside_baseline()) {
          INFO(name_of(isa) << ", " << n << " points");
          const GpPrediction copy = predicted(isa);
          CHECK(std::memcmp(&copy.distance, &baseline.distance, sizeof(double)) == 0);
          CHECK(std::memcmp(copy.gradient.data(), baseline.gradient.data(), 3 * sizeof(double)) == 0);
          CHECK(std::memcmp(&copy.variance, &baseline.variance, sizeof(double)) == 0);
        }
      }
    }
  }
}
