// SPDX-License-Identifier: GPL-3.0-or-later
// Noise stages against the published closed forms, each stage on its own.
#include "scenes.hpp"
#include "sim/noise.hpp"
#include "sim/simulation.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <set>

using namespace sonomap::sim;

namespace {

DepthImage flat(int w, int h, float z, float incidence = 0.0f) {
  DepthImage image;
  image.width = w;
  image.height = h;
  image.z.assign(static_cast<std::size_t>(w) * h, z);
  image.incidence.assign(image.z.size(), incidence);
  return image;
}

double std_dev(const std::vector<float>& values, double mean) {
  double sum = 0.0;
  for (float v : values) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / (values.size() - 1));
}

double mean_of(const std::vector<float>& values) {
  double sum = 0.0;
  for (float v : values) sum += v;
  return sum / values.size();
}

}  // namespace

TEST_CASE("axial noise std at range z matches Nguyen et al. 2012 within 5%", "[sim][noise]") {
  const NoiseKey key{7, 0, 3};
  for (double z : {0.8, 2.0, 4.0}) {
    const DepthImage out = add_axial_noise(flat(200, 200, static_cast<float>(z)), key);
    const double expected = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);  // facing the sensor
    const double mean = mean_of(out.z);
    CHECK(mean == Approx(z).margin(3.0 * expected / 200.0 + 1e-6));
    CHECK(std_dev(out.z, mean) == Approx(expected).epsilon(0.05));
  }
}

TEST_CASE("axial noise grows at grazing incidence as Nguyen et al. 2012 say", "[sim][noise]") {
  const double z = 2.0, theta = 70.0 * M_PI / 180.0;
  const DepthImage out =
      add_axial_noise(flat(200, 200, static_cast<float>(z), static_cast<float>(theta)), NoiseKey{7, 0, 4});
  const double expected = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) +
                          0.0001 / std::sqrt(z) * theta * theta / ((M_PI / 2 - theta) * (M_PI / 2 - theta));
  CHECK(std_dev(out.z, mean_of(out.z)) == Approx(expected).epsilon(0.05));
}

TEST_CASE("disparity quantisation gives depths f b / (k / 8) with the steps between them", "[sim][noise]") {
  const double f = 525.0, b = 0.075, step = 0.125;
  DepthImage ramp = flat(1000, 1, 0.0f);
  for (int i = 0; i < 1000; ++i) ramp.z[i] = static_cast<float>(0.5 + 4.5 * i / 999.0);
  const DepthImage out = quantise_disparity(ramp, f, b, step);
  std::set<float> levels;
  for (int i = 0; i < 1000; ++i) {
    const double k = f * b / (out.z[i] * step);  // disparity in 1/8 px steps: an integer
    CHECK(std::abs(k - std::round(k)) < 1e-3);
    // Nearest level: within half a disparity step, i.e. half the depth step z^2 step / (f b).
    const double z = ramp.z[i];
    CHECK(std::abs(out.z[i] - z) <= 0.5 * z * z * step / (f * b) * 1.01 + 1e-6);
    levels.insert(out.z[i]);
  }
  // Near 4 m the step between neighbouring levels is f b / (k step) - f b / ((k + 1) step).
  const double k4 = std::round(f * b / (4.0 * step));
  const float level = static_cast<float>(f * b / (k4 * step));
  const float next = static_cast<float>(f * b / ((k4 - 1) * step));
  CHECK(levels.count(level) == 1);
  CHECK(levels.count(next) == 1);
  CHECK(next - level == Approx(f * b / step * (1.0 / (k4 - 1) - 1.0 / k4)).epsilon(1e-5));
  // First order (Khoshelham & Elberink): dz = z^2 step / (f b), ~5 cm at 4 m for Kinect v1.
  CHECK(next - level == Approx(4.0 * 4.0 * step / (f * b)).epsilon(0.03));
}

TEST_CASE("lateral jitter moves a step edge by N(0, 0.8 px) rounded to pixels", "[sim][noise]") {
  // Left half 1 m, right half 2 m, facing the sensor (sigma_L = 0.8 px). The pixel just left of
  // the edge takes the right side's depth when its horizontal offset rounds to >= 1, i.e.
  // with probability 1 - Phi(0.5 / 0.8); two pixels away, 1 - Phi(1.5 / 0.8).
  const int w = 20, h = 20000, edge = 10;
  DepthImage step = flat(w, h, 1.0f);
  for (int v = 0; v < h; ++v)
    for (int u = edge; u < w; ++u) step.z[static_cast<std::size_t>(v) * w + u] = 2.0f;
  const DepthImage out = jitter_lateral(step, NoiseKey{11, 0, 0});
  auto fraction_far = [&](int u) {
    int n = 0;
    for (int v = 0; v < h; ++v) n += out.z[static_cast<std::size_t>(v) * w + u] == 2.0f;
    return static_cast<double>(n) / h;
  };
  auto upper_tail = [](double x) { return 0.5 * std::erfc(x / std::sqrt(2.0)); };
  CHECK(fraction_far(edge - 1) == Approx(upper_tail(0.5 / 0.8)).margin(0.01));
  CHECK(fraction_far(edge - 2) == Approx(upper_tail(1.5 / 0.8)).margin(0.005));
  CHECK(fraction_far(0) == 0.0);
  // Sigma grows at grazing incidence: 0.8 + 0.035 theta / (pi/2 - theta).
  CHECK(lateral_sigma_px(0.0) == Approx(0.8));
  CHECK(lateral_sigma_px(M_PI / 4) == Approx(0.8 + 0.035));
}

TEST_CASE("edge, grazing and dropout invalidation", "[sim][noise]") {
  DepthImage reference = flat(10, 10, 1.0f);
  for (int v = 0; v < 10; ++v) reference.z[static_cast<std::size_t>(v) * 10 + 9] = 0.0f;  // no surface
  for (int v = 0; v < 10; ++v) reference.z[static_cast<std::size_t>(v) * 10 + 5] = 1.05f;  // small step
  for (int u = 0; u < 10; ++u) reference.z[5 * 10 + u] = u == 9 ? 0.0f : 3.0f;             // big step
  const DepthImage out = invalidate_edges(reference, reference, 0.1);
  auto z = [&](int u, int v) { return out.z[static_cast<std::size_t>(v) * 10 + u]; };
  CHECK(z(8, 0) == 0.0f);   // next to "no surface"
  CHECK(z(4, 0) == 1.0f);   // a 5 cm step is not an edge
  CHECK(z(2, 4) == 0.0f);   // next to the 3 m row
  CHECK(z(2, 5) == 0.0f);   // on the 3 m row
  CHECK(z(2, 2) == 1.0f);

  const DepthImage slanted = flat(4, 1, 2.0f, static_cast<float>(85.0 * M_PI / 180.0));
  CHECK(invalidate_grazing(slanted, 80.0 * M_PI / 180.0).z[0] == 0.0f);
  CHECK(invalidate_grazing(slanted, 89.0 * M_PI / 180.0).z[0] == 2.0f);

  const DepthImage dropped = drop_out(flat(200, 200, 1.0f), 0.3, NoiseKey{1, 0, 0});
  int zeros = 0;
  for (float d : dropped.z) zeros += d == 0.0f;
  CHECK(zeros / 40000.0 == Approx(0.3).margin(0.01));
}

TEST_CASE("model None gives exact depth, Kinect stays near the truth", "[sim][noise]") {
  Scenario s = test::wall_scenario(2.5);
  s.camera.width = 160;
  s.camera.height = 120;
  s.camera.fx = s.camera.fy = 130.0;
  s.camera.cx = 79.5;
  s.camera.cy = 59.5;
  s.noise.model = NoiseSpec::Model::None;
  s.noise.dropout = 0.5;  // ignored by None
  Simulation exact(s);
  for (float z : exact.render(0).depth) REQUIRE(z == Approx(2.5).epsilon(1e-5));

  s.noise.model = NoiseSpec::Model::Kinect;
  s.noise.dropout = 0.0;
  Simulation noisy(s);
  const auto depth = noisy.render(0).depth;
  int valid = 0, different = 0;
  for (float z : depth) {
    if (z == 0.0f) continue;
    ++valid;
    different += std::abs(z - 2.5f) > 1e-4f;
    // Within 5 sigma of the axial noise plus one quantisation step.
    CHECK(std::abs(z - 2.5) < 5 * (0.0012 + 0.0019 * 2.1 * 2.1) + 2.5 * 2.5 * 0.125 / (130.0 * 0.075));
  }
  CHECK(valid == 160 * 120);  // a frontal wall: no edges, no grazing, no dropout
  CHECK(different > valid / 2);
}

TEST_CASE("the whole noise model is identical with 1 and 2 threads and keeps the axial mean and std",
          "[sim][noise][determinism]") {
  // A frontal wall at 3 m over a full 640x480 frame, every stage on except dropout (so every
  // pixel keeps its axial sample): rows are spread over the threads, each row has its own stream.
  const double z = 3.0;
  DepthImage wall = flat(640, 480, static_cast<float>(z));
  NoiseSpec spec;
  spec.model = NoiseSpec::Model::Kinect;
  spec.quantisation = false;  // keeps the samples continuous for the std check
  spec.dropout = 0.0;
  const NoiseKey key{5, 0, 12};
  auto noisy = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return apply_noise(wall, spec, 525.0, key);
  };
  const DepthImage one = noisy(1), two = noisy(2);
  REQUIRE(one.z.size() == wall.z.size());
  CHECK(std::memcmp(one.z.data(), two.z.data(), one.z.size() * sizeof(float)) == 0);
  CHECK(one.z != wall.z);
  // Nguyen et al. 2012, facing the sensor: sigma_z = 0.0012 + 0.0019 (z - 0.4)^2.
  const double expected = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
  const double n = static_cast<double>(one.z.size()), mean = mean_of(one.z);
  CHECK(mean == Approx(z).margin(5.0 * expected / std::sqrt(n)));
  CHECK(std_dev(one.z, mean) == Approx(expected).epsilon(5.0 * std::sqrt(0.5 / n)));
}

TEST_CASE("the fused noise model equals its stages run one by one", "[sim][noise][determinism]") {
  // A slanted floor with a step and a hole: every stage changes something. The stages are
  // chained by hand in the documented order, each on a copy (the independent path).
  DepthImage truth = flat(64, 48, 2.0f, static_cast<float>(50.0 * M_PI / 180.0));
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * 64 + u;
      truth.z[p] = u < 30 ? 1.0f + 0.02f * v : 3.0f;
      truth.incidence[p] = static_cast<float>((20.0 + u) * M_PI / 180.0);
      if (u > 50 && v > 40) truth.z[p] = 0.0f;
    }
  NoiseSpec spec;
  spec.model = NoiseSpec::Model::Kinect;
  spec.dropout = 0.1;
  const NoiseKey key{3, 0, 9};
  DepthImage staged = jitter_lateral(truth, key);
  staged = add_axial_noise(staged, key);
  staged = quantise_disparity(staged, 525.0, spec.baseline, spec.disparity_step);
  staged = invalidate_grazing(staged, spec.grazing_angle);
  staged = invalidate_edges(staged, truth, spec.edge_threshold);
  staged = drop_out(staged, spec.dropout, key);
  const DepthImage fused = apply_noise(truth, spec, 525.0, key);
  REQUIRE(fused.z.size() == staged.z.size());
  CHECK(std::memcmp(fused.z.data(), staged.z.data(), fused.z.size() * sizeof(float)) == 0);
  int zeros = 0;
  for (float z : fused.z) zeros += z == 0.0f;
  CHECK(zeros > 64 * 48 / 10);  // dropout, edges, grazing and the hole all took pixels
  CHECK(zeros < 64 * 48 / 2);
}
