// SPDX-License-Identifier: GPL-3.0-or-later
// Rasters from the map against the exact ground truth, on scenes built here: the map must hold
// what one camera view cannot (a full circle after a turn) and forget what has gone.
#include "../vector_isas.hpp"
#include "core/depth_only.hpp"
#include "core/open3d_tsdf.hpp"
#include "core/rasterise_map.hpp"
#include "core/rasteriser.hpp"
#include "core/tsdf.hpp"
#include "core/vdb_gpdf.hpp"
#include "eval/ground_truth.hpp"
#include "eval/metrics.hpp"
#include "sim/primitives.hpp"
#include "sim/simulation.hpp"
#include "sim/trajectory.hpp"
#include "sim/world_geometry.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

using namespace sonomap;

namespace {

constexpr double kDeg = M_PI / 180.0;

sim::StaticObject object(sim::PrimitiveSpec::Kind kind, const Eigen::Vector3d& size,
                         const Eigen::Vector3d& position) {
  sim::StaticObject o;
  o.shape.kind = kind;
  o.shape.size = size;
  o.pose.translation() = position;
  o.mesh = sim::triangulate(o.shape);
  return o;
}

sim::Keyframe key(double t, const Eigen::Vector3d& p, double yaw_deg) {
  return sim::Keyframe{t, p, Eigen::Quaterniond(Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()))};
}

// A 320 x 240 camera (half the Kinect's resolution and focal length), 1.5 m above the floor,
// tilted 15 degrees down, turning one full circle in 3 s at 30 Hz inside a 4 x 4 x 2.5 m room
// with a 0.6 x 0.6 x 1 m box.
sim::Scenario turning_in_a_room(sim::NoiseSpec::Model noise) {
  sim::Scenario s;
  s.name = "turn";
  s.seed = 11;
  s.frames = 91;
  s.statics.push_back(object(sim::PrimitiveSpec::Kind::Room, {4.0, 4.0, 2.5}, {0, 0, 0}));
  s.statics.push_back(object(sim::PrimitiveSpec::Kind::Box, {0.6, 0.6, 1.0}, {1.0, 0.6, 0}));
  s.camera.width = 320;
  s.camera.height = 240;
  s.camera.fx = s.camera.fy = 262.5;
  s.camera.cx = 159.5;
  s.camera.cy = 119.5;
  s.camera.body_T_camera =
      Eigen::Isometry3d(Eigen::AngleAxisd(15 * kDeg, Eigen::Vector3d::UnitY())) *
      sim::CameraSpec::default_body_T_camera();
  s.noise.model = noise;
  const Eigen::Vector3d eye(-0.2, -0.1, 1.5);
  s.body.keyframes = {key(0, eye, 0), key(1, eye, 120), key(2, eye, 240), key(3, eye, 360)};
  return s;
}

struct Evaluation {
  eval::RasterMetrics circle, cylinder;
};

Evaluation evaluate(Mapper& mapper, const sim::Scenario& s, const Frame& frame) {
  RasterConfig config;
  const RasterOrigin origin = raster_origin(frame.world_T_body, s.ground_z);
  std::vector<Eigen::Vector3f> surface;
  mapper.surface_points(origin.position, config.max_range, surface);
  Rasteriser rasteriser(config);
  rasteriser.reset(origin);
  rasteriser.add(surface);
  const auto truth = eval::ground_truth_rasters(sim::world_triangles(s, frame.time),
                                                   raster_origin(sim::pose_at(s.body, frame.time)), config);
  eval::MetricsConfig metrics;
  metrics.ghost_tolerance = 0.10;
  return {eval::compare(rasteriser.circle(), truth.circle, metrics),
          eval::compare(rasteriser.cylinder(), truth.cylinder, metrics)};
}

Evaluation map_full_turn(Mapper& mapper, sim::NoiseSpec::Model noise) {
  const sim::Scenario s = turning_in_a_room(noise);
  sim::Simulation simulation(s);
  Frame frame;
  for (int i = 0; i < simulation.frame_count(); ++i) {
    frame = simulation.render(i);
    mapper.integrate(frame);
  }
  return evaluate(mapper, s, frame);
}

}  // namespace

TEST_CASE("after a full turn in a room the VDB-GPDF circle covers every bin within half a voxel",
          "[map][raster]") {
  VdbGpdf mapper;  // reference defaults: 5 cm global voxels
  const Evaluation e = map_full_turn(mapper, sim::NoiseSpec::Model::None);
  INFO("circle coverage " << e.circle.coverage << ", RMSE " << e.circle.rmse << " m, ghosts "
                          << e.circle.ghosts << ", RMSE off silhouette edges " << e.circle.rmse_off_edges
                          << " m, edge bins " << e.circle.edge_cells);
  CHECK(e.circle.truth_occupied == 360);
  CHECK(e.circle.coverage == 1.0);
  // The RMSE over every bin is dominated by silhouette slivers (eval/metrics.hpp); the
  // surfaces themselves are measured off the truth's silhouette edges.
  CHECK(e.circle.edge_cells <= 8);  // the box's two silhouettes
  CHECK(e.circle.rmse_off_edges < 0.5 * 0.05);
  CHECK(e.circle.ghosts == 0);
}

TEST_CASE("with Kinect noise the VDB-GPDF circle still covers every bin within one voxel",
          "[map][raster][noise]") {
  VdbGpdf mapper;
  const Evaluation e = map_full_turn(mapper, sim::NoiseSpec::Model::Kinect);
  INFO("circle coverage " << e.circle.coverage << ", RMSE off silhouette edges " << e.circle.rmse_off_edges);
  CHECK(e.circle.coverage == 1.0);
  CHECK(e.circle.rmse_off_edges < 0.05);
}

TEST_CASE("after a full turn the TSDF peer's circle covers every bin within one voxel",
          "[map][raster][tsdf]") {
  Tsdf mapper;
  const Evaluation e = map_full_turn(mapper, sim::NoiseSpec::Model::None);
  INFO("circle coverage " << e.circle.coverage << ", RMSE off silhouette edges " << e.circle.rmse_off_edges);
  CHECK(e.circle.coverage == 1.0);
  CHECK(e.circle.rmse_off_edges < 0.05);
}

TEST_CASE("asked for a band of heights, every map leaves out the floor and the walls above it and "
          "nothing else", "[map][raster][band]") {
  const sim::Scenario s = turning_in_a_room(sim::NoiseSpec::Model::None);
  sim::Simulation simulation(s);
  std::vector<std::unique_ptr<Mapper>> maps;
  maps.push_back(std::make_unique<VdbGpdf>());
  maps.push_back(std::make_unique<Tsdf>());
  maps.push_back(std::make_unique<Open3dTsdf>());
  maps.push_back(std::make_unique<DepthOnlyMapper>());
  Frame frame;
  for (int i = 0; i <= 45; i += 5) {  // half a turn
    frame = simulation.render(i);
    for (auto& map : maps) map->integrate(frame);
  }
  const RasterConfig config;
  const RasterOrigin origin = raster_origin(frame.world_T_body, s.ground_z);
  for (const auto& map : maps) {
    INFO(map->name());
    std::vector<Eigen::Vector3f> all, band;
    map->surface_points(origin.position, config.max_range, all);
    // The whole surface has the floor (z = 0) and the walls up to where the camera, tilted
    // down, stops seeing them (about 1.8 m).
    const auto lowest = std::min_element(all.begin(), all.end(), [](auto& a, auto& b) { return a.z() < b.z(); });
    const auto highest = std::max_element(all.begin(), all.end(), [](auto& a, auto& b) { return a.z() < b.z(); });
    REQUIRE(lowest != all.end());
    CHECK(lowest->z() < 0.05);
    CHECK(highest->z() > 1.7);
    // A band from 1.0 to 1.2 m holds the walls' and the box's samples at those heights, in the
    // same order, and only those.
    map->surface_points_in_band(origin.position, config.max_range, 1.0, 1.2, band);
    std::vector<Eigen::Vector3f> expected;
    for (const Eigen::Vector3f& p : all)
      if (p.z() >= 1.0 && p.z() <= 1.2) expected.push_back(p);
    CHECK(expected.size() > 100);
    CHECK(band == expected);
    // The same band read in place: the spans hold the band's samples in the same order, among
    // others of their leaves outside the band.
    std::vector<SampleSpan> spans;
    std::vector<Eigen::Vector3f> copied, in_band;
    map->surface_spans_in_band(origin.position, config.max_range, 1.0, 1.2, spans, copied);
    const double r2 = config.max_range * config.max_range;
    for (const SampleSpan& span : spans)
      for (const Eigen::Vector3f* p = span.points; p != span.points + span.count; ++p)
        if (p->z() >= 1.0 && p->z() <= 1.2 &&
            (p->head<2>().cast<double>() - origin.position.head<2>()).squaredNorm() <= r2)
          in_band.push_back(*p);
    CHECK(in_band == band);
    // The rasters built from the band are the rasters of the whole surface, cell for cell,
    // and read fewer samples than there are.
    Rasteriser from_band(config), from_all(config);
    RasterScratch scratch;
    rasterise_map(*map, origin, from_band, scratch);
    from_all.reset(origin);
    from_all.add(all);
    size_t read = 0;
    for (const SampleSpan& span : scratch.spans) read += span.count;
    CHECK(read < all.size());
    CHECK(same_bits(from_band.circle().bins, from_all.circle().bins));
    CHECK(same_bits(from_band.cylinder().cells, from_all.cylinder().cells));
  }
}
