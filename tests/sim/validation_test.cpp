// SPDX-License-Identifier: GPL-3.0-or-later
// Bad scenarios are refused by the Simulation constructor with a message naming the problem.
#include "scenes.hpp"
#include "sim/primitives.hpp"
#include "sim/simulation.hpp"

#include <catch2/catch.hpp>

using namespace sonomap::sim;

TEST_CASE("Simulation rejects bad scenarios, naming what is wrong", "[sim][validation]") {
  const Scenario good = test::wall_scenario(2.0);
  REQUIRE_NOTHROW(Simulation(good));

  Scenario nan_mesh = good;
  nan_mesh.statics[0].mesh = triangulate(nan_mesh.statics[0].shape);
  nan_mesh.statics[0].mesh.vertices[2].x() = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(Simulation(nan_mesh), Catch::Contains("'wall'") && Catch::Contains("vertex 2"));

  Scenario zero_fx = good;
  zero_fx.camera.fx = 0.0;
  CHECK_THROWS_WITH(Simulation(zero_fx), Catch::Contains("fx"));

  Scenario negative_fy = good;
  negative_fy.camera.fy = -525.0;
  CHECK_THROWS_WITH(Simulation(negative_fy), Catch::Contains("fy"));

  Scenario zero_width = good;
  zero_width.camera.width = 0;
  CHECK_THROWS_WITH(Simulation(zero_width), Catch::Contains("resolution"));

  Scenario ranges = good;
  ranges.camera.max_range = ranges.camera.min_range;
  CHECK_THROWS_WITH(Simulation(ranges), Catch::Contains("max_range"));

  Scenario keyframes = good;
  keyframes.body.keyframes.push_back(keyframes.body.keyframes[0]);  // same time twice
  CHECK_THROWS_WITH(Simulation(keyframes), Catch::Contains("body") && Catch::Contains("keyframe 1"));

  Scenario empty = good;
  empty.body.keyframes.clear();
  CHECK_THROWS_WITH(Simulation(empty), Catch::Contains("no keyframes"));

  Scenario mover_empty = good;
  MovingObject m;
  m.name = "walker";
  mover_empty.movers.push_back(m);
  CHECK_THROWS_WITH(Simulation(mover_empty), Catch::Contains("'walker'") && Catch::Contains("no keyframes"));

  Scenario dropout = good;
  dropout.noise.dropout = 1.5;
  CHECK_THROWS_WITH(Simulation(dropout), Catch::Contains("dropout"));

  Scenario frames = good;
  frames.frames = 0;
  CHECK_THROWS_AS(Simulation(frames), std::invalid_argument);

  Simulation sim(good);
  CHECK_THROWS_AS(sim.render(-1), std::out_of_range);
}
