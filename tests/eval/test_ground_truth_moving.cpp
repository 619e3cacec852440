// SPDX-License-Identifier: GPL-3.0-or-later
// Ground truth of a moving object at time t, through the simulator's world geometry.
#include "eval/ground_truth.hpp"
#include "sim/world_geometry.hpp"

#include <catch2/catch.hpp>

using namespace sonomap;
using namespace sonomap::eval;

namespace {

// A 0.4 x 0.4 x 1.8 m box walking from x = 3 (t = 0) to x = 1.5 (t = 1) along the x axis,
// gone from t = 0.8; the sensor stands at the origin looking along +x.
sim::Scenario walker() {
  sim::Scenario scenario;
  sim::MovingObject person;
  person.name = "person";
  person.shape.kind = sim::PrimitiveSpec::Kind::Box;
  person.shape.size = Eigen::Vector3d(0.4, 0.4, 1.8);
  sim::Keyframe start, end;
  start.time = 0.0;
  start.position = Eigen::Vector3d(3.0, 0.0, 0.0);
  end.time = 1.0;
  end.position = Eigen::Vector3d(1.5, 0.0, 0.0);
  person.trajectory.keyframes = {start, end};
  person.disappear_time = 0.8;
  scenario.movers.push_back(person);
  return scenario;
}

GroundTruthRasters truth_at(const sim::Scenario& scenario, double t) {
  return ground_truth_rasters(sim::world_triangles(scenario, t), RasterOrigin{}, RasterConfig{});
}

}  // namespace

TEST_CASE("A moving box is in the truth where it is at time t", "[ground_truth]") {
  const sim::Scenario scenario = walker();
  // Front face at x(t) - 0.2 with x(t) = 3 - 1.5 t; bins 0 and 359 contain the face normal.
  for (double t : {0.0, 0.5, 0.75}) {
    INFO("t = " << t);
    const double front = 3.0 - 1.5 * t - 0.2;
    const GroundTruthRasters truth = truth_at(scenario, t);
    CHECK(truth.circle.bins[0].range == Approx(front).epsilon(1e-6));
    CHECK(truth.circle.bins[359].range == Approx(front).epsilon(1e-6));
    CHECK_FALSE(truth.circle.bins[90].known());
    // 1.8 m tall: rows up to [1.7, 1.8] see it, rows from 1.8 m up do not.
    CHECK(truth.cylinder.at(16, 0).known());
    CHECK_FALSE(truth.cylinder.at(18, 0).known());
  }
  // Gone at t = 0.8: nothing left.
  CHECK(truth_at(scenario, 0.9).circle.known_count() == 0);
}
