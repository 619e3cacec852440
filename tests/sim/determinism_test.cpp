// SPDX-License-Identifier: GPL-3.0-or-later
// Same scenario and seed: bit-identical frames across reruns, render order, thread counts and
// instruction sets.
#include "../vector_isas.hpp"
#include "scenes.hpp"
#include "sim/depth_camera.hpp"
#include "sim/noise.hpp"
#include "sim/simulation.hpp"
#include "sim/world.hpp"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

using namespace sonomap::sim;
using sonomap::Frame;
using sonomap::ScopedVectorIsa;
using sonomap::VectorIsa;
using sonomap::vector_isa;

namespace {

// FNV-1a over the depth bytes and both given poses.
std::uint64_t hash_of(const Frame& f) {
  std::uint64_t h = 1469598103934665603ULL;
  auto add = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ULL;
  };
  add(f.depth.data(), f.depth.size() * sizeof(float));
  add(f.world_T_camera.matrix().data(), 16 * sizeof(double));
  add(f.world_T_body.matrix().data(), 16 * sizeof(double));
  return h;
}

// A noisy, moving scene: a box and a sphere in a room, the body walking and turning, with
// every noise stage and localisation drift on.
Scenario busy_scenario() {
  Scenario s;
  StaticObject room;
  room.name = "room";
  room.shape.kind = PrimitiveSpec::Kind::Room;
  room.shape.size = Eigen::Vector3d(8.0, 6.0, 2.8);
  s.statics.push_back(room);
  StaticObject pillar;
  pillar.shape.kind = PrimitiveSpec::Kind::Cylinder;
  pillar.shape.radius = 0.3;
  pillar.shape.height = 2.0;
  pillar.pose.translation() = Eigen::Vector3d(2.0, 1.0, 0.0);
  s.statics.push_back(pillar);
  MovingObject ball;
  ball.shape.kind = PrimitiveSpec::Kind::Sphere;
  ball.trajectory.keyframes = {Keyframe{0.0, Eigen::Vector3d(2.5, -2.0, 1.0), Eigen::Quaterniond::Identity()},
                               Keyframe{1.0, Eigen::Vector3d(2.5, 2.0, 1.0), Eigen::Quaterniond::Identity()}};
  s.movers.push_back(ball);
  s.body.keyframes = {
      Keyframe{0.0, Eigen::Vector3d(-1.0, 0.0, 1.5), Eigen::Quaterniond::Identity()},
      Keyframe{1.0, Eigen::Vector3d(0.0, 0.5, 1.5),
               Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitZ()))}};
  s.camera.width = 160;
  s.camera.height = 120;
  s.camera.fx = s.camera.fy = 130.0;
  s.camera.cx = 79.5;
  s.camera.cy = 59.5;
  s.noise.model = NoiseSpec::Model::Kinect;
  s.noise.dropout = 0.05;
  s.localisation.translation_noise = 0.01;
  s.localisation.yaw_noise = 0.01;
  s.localisation.translation_drift = 0.05;
  s.localisation.yaw_drift = 0.02;
  s.frames = 30;
  s.seed = 42;
  return s;
}

// busy_scenario at 640x480: enough rows for both threads, every noise stage busy.
Scenario full_frame_scenario() {
  Scenario s = busy_scenario();
  s.camera.width = 640;
  s.camera.height = 480;
  s.camera.fx = s.camera.fy = 525.0;
  s.camera.cx = 319.5;
  s.camera.cy = 239.5;
  return s;
}

}  // namespace

TEST_CASE("frames are identical across reruns and in any render order", "[sim][determinism]") {
  Simulation first(busy_scenario());
  std::vector<std::uint64_t> in_order;
  for (int i = 0; i < 30; i += 3) in_order.push_back(hash_of(first.render(i)));

  Simulation second(busy_scenario());
  for (int k = static_cast<int>(in_order.size()) - 1; k >= 0; --k)
    CHECK(hash_of(second.render(3 * k)) == in_order[k]);

  Scenario reseeded = busy_scenario();
  reseeded.seed = 43;
  Simulation other(reseeded);
  CHECK(hash_of(other.render(9)) != in_order[3]);
}

TEST_CASE("frames are identical with 1 and 2 threads", "[sim][determinism]") {
  const Scenario s = full_frame_scenario();
  std::uint64_t one = 0, two = 0;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    Simulation sim(s);
    one = hash_of(sim.render(17));
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    Simulation sim(s);
    two = hash_of(sim.render(17));
  }
  CHECK(one == two);
}

namespace {

// Frame `index` rendered with the given instruction set and thread count.
Frame rendered(const Scenario& s, int index, VectorIsa isa, int threads) {
  const ScopedVectorIsa code(isa);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Simulation sim(s);
  return sim.render(index);
}

// The exact image (depth and incidence) of frame 17 of `s`, rays cast with `isa`.
DepthImage traced(const Scenario& s, VectorIsa isa) {
  const ScopedVectorIsa code(isa);
  const Simulation sim(s);  // for the meshes and the pose
  World world(sim.scenario());
  const double t = sim.time_of(17);
  world.set_time(t);
  return DepthCamera(s.camera).trace(world, sim.true_camera_pose(t));
}

DepthImage noisy(const DepthImage& truth, const NoiseSpec& spec, VectorIsa isa, int threads) {
  const ScopedVectorIsa code(isa);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  return apply_noise(truth, spec, 525.0, NoiseKey{42, 0, 17});
}

}  // namespace

// The vectorised loops (core/vector_isa.hpp) must give the baseline's bits. Compared before
// quantisation, which would hide a difference in the last bits of the noise or the angles.
TEST_CASE("the baseline, AVX2 and AVX-512 code give the same rays and noise to the bit, with 1 and 2 threads",
          "[sim][determinism]") {
  // With a mover (rays through the instances) and without (rays straight into the statics).
  Scenario still_world = full_frame_scenario();
  still_world.movers.clear();
  for (const Scenario& s : {full_frame_scenario(), still_world}) {
    INFO("movers: " << s.movers.size());
    const DepthImage truth = traced(s, VectorIsa::Baseline);
    NoiseSpec spec = s.noise;
    spec.quantisation = false;
    const DepthImage noise = noisy(truth, spec, VectorIsa::Baseline, 1);
    CHECK(same_bits(noise.z, noisy(truth, spec, VectorIsa::Baseline, 2).z));
    for (VectorIsa isa : vector_isas_beside_baseline()) {
      INFO("instruction set " << static_cast<int>(isa));
      const DepthImage rays = traced(s, isa);
      CHECK(same_bits(rays.z, truth.z));
      CHECK(same_bits(rays.incidence, truth.incidence));
      CHECK(same_bits(noisy(truth, spec, isa, 1).z, noise.z));
      CHECK(same_bits(noisy(truth, spec, isa, 2).z, noise.z));
      const Frame baseline = rendered(s, 17, VectorIsa::Baseline, 1), vectorised = rendered(s, 17, isa, 2);
      CHECK(same_bits(baseline.depth, vectorised.depth));
      REQUIRE(baseline.points_camera.size() == vectorised.points_camera.size());
      CHECK(std::memcmp(baseline.points_camera.data(), vectorised.points_camera.data(),
                        baseline.points_camera.size() * sizeof(Eigen::Vector3f)) == 0);
    }
    // The comparisons see every stage at work: returns, grazing angles, dropped and moved pixels.
    std::size_t returns = 0, grazing = 0, dropped = 0, moved = 0;
    for (std::size_t p = 0; p < truth.z.size(); ++p) {
      returns += truth.z[p] > 0.0f;
      grazing += truth.incidence[p] > M_PI / 3;
      dropped += truth.z[p] > 0.0f && noise.z[p] == 0.0f;
      moved += noise.z[p] > 0.0f && std::abs(noise.z[p] - truth.z[p]) > 0.05f;  // jittered across an edge
    }
    CHECK(returns > truth.z.size() / 2);
    CHECK(grazing > truth.z.size() / 20);
    CHECK(dropped > returns / 40);  // dropout 5 %, edges, grazing
    CHECK(moved > 0);
  }
}

// Embree's 16-ray packets (4x4 pixels, chosen with AVX-512) and 8-ray packets (4x2, chosen
// elsewhere) trace the same rays: the same hits and angles to the bit, whatever the machine.
// On an image of 643 x 482 pixels the last tiles of a row and of a column hang over the
// image's edge; rows 480 and 481 fill a whole 4 x 2 tile but half a 4 x 4 one.
TEST_CASE("the rays are the same whatever Embree's packet width", "[sim][determinism]") {
  Scenario still_world = full_frame_scenario();
  still_world.movers.clear();
  Scenario odd_size = full_frame_scenario();
  odd_size.camera.width = 643;
  odd_size.camera.height = 482;
  for (const Scenario& s : {full_frame_scenario(), still_world, odd_size}) {
    INFO("movers: " << s.movers.size() << ", image " << s.camera.width << " x " << s.camera.height);
    const Simulation sim(s);
    World world(sim.scenario());
    const double t = sim.time_of(17);
    world.set_time(t);
    const PinholeRays rays = PinholeRays::of(s.camera, sim.true_camera_pose(t));
    RayHits by8, by16;
    world.cast(rays, by8, World::Packet::Rays8);
    world.cast(rays, by16, World::Packet::Rays16);
    CHECK(same_bits(by8.z, by16.z));
    CHECK(same_bits(by8.incidence, by16.incidence));
    const auto hits = std::count_if(by8.z.begin(), by8.z.end(), [](float z) { return std::isfinite(z); });
    CHECK(hits > static_cast<long>(by8.z.size() / 2));  // the comparison sees surfaces, not sky
  }
}

TEST_CASE("statics cast directly read the same as through their instance beside an absent mover",
          "[sim][determinism]") {
  // Without movers the rays skip the instance level; a mover that is never present keeps it.
  Scenario direct = full_frame_scenario();
  direct.movers.clear();
  Scenario instanced = full_frame_scenario();
  instanced.movers.front().appear_time = 1e9;
  const Frame a = rendered(direct, 17, vector_isa(), 1), b = rendered(instanced, 17, vector_isa(), 1);
  CHECK(same_bits(a.depth, b.depth));
}
