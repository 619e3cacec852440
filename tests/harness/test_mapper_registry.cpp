// SPDX-License-Identifier: GPL-3.0-or-later
// The mapper registry: a program's mapper is built by name like the built-ins, gets the run's
// voxel and settings, and its bad settings become bad input (exit status 2) naming the mapper.
#include "core/depth_only.hpp"
#include "harness/app/mapper_registry.hpp"
#include "harness/support/errors.hpp"
#include "tests/core/test_vdb_gpdf_scene.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <stdexcept>

using sonomap::harness::InputError;
using sonomap::harness::make_mapper;
using sonomap::harness::mapper_names;

namespace {

struct Seen {
  double voxel = -1.0;
  std::vector<sonomap::MapperSetting> settings;
};

Seen& seen() {
  static Seen s;
  return s;
}

std::unique_ptr<sonomap::Mapper> recording_factory(double voxel,
                                                   const std::vector<sonomap::MapperSetting>& settings) {
  seen() = {voxel, settings};
  for (const auto& s : settings)
    if (s.key != "ok") throw std::invalid_argument(s.source + ": no setting '" + s.key + "'");
  return std::make_unique<sonomap::DepthOnlyMapper>();
}

}  // namespace

TEST_CASE("mapper registry: a registered mapper sits after the built-ins and gets the run's voxel and settings") {
  sonomap::register_mapper("registry-test_1", recording_factory);
  const auto names = mapper_names();
  REQUIRE(names.size() >= 5);
  CHECK(std::vector<std::string>(names.begin(), names.begin() + 4) ==
        std::vector<std::string>{"vdb_gpdf", "tsdf", "open3d", "depth_only"});
  CHECK(names.back() == "registry-test_1");

  const auto mapper = make_mapper("registry-test_1", 0.2, {{"ok", "3", "--set mapper.ok=3"}});
  REQUIRE(mapper);
  CHECK(mapper->name() == "depth_only");
  CHECK(seen().voxel == 0.2);
  REQUIRE(seen().settings.size() == 1);
  CHECK(seen().settings[0].value == "3");

  try {
    make_mapper("registry-test_1", 0.0, {{"bogus", "1", "--set mapper.bogus=1"}});
    FAIL("a bad setting was accepted");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "mapper 'registry-test_1': --set mapper.bogus=1: no setting 'bogus'");
  }
  try {
    make_mapper("registry-test_2", 0.0, {});
    FAIL("an unknown mapper was built");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("known: vdb_gpdf, tsdf, open3d, depth_only, registry-test_1)") !=
          std::string::npos);
  }
  CHECK_THROWS_AS(make_mapper("registry-test_1", -0.1, {}), InputError);
}

TEST_CASE("mapper registry: malformed names, taken names and empty factories are refused") {
  for (const std::string name : {"", "two words", "a/b", "vdb_gpdf", "open3d", "depth_only"})
    CHECK_THROWS_AS(sonomap::register_mapper(name, recording_factory), std::invalid_argument);
  CHECK_THROWS_AS(sonomap::register_mapper("empty", sonomap::MapperFactory{}), std::invalid_argument);
  sonomap::register_mapper("once", recording_factory);
  CHECK_THROWS_AS(sonomap::register_mapper("once", recording_factory), std::invalid_argument);
  const auto names = mapper_names();
  CHECK(std::count(names.begin(), names.end(), "once") == 1);
}

TEST_CASE("mapper registry: every built-in mapper's surface_points replaces what the vector held") {
  // A wall 2 m ahead of a camera 1.5 m up: asking twice gives the same samples, not twice as
  // many, and a stale point left in the vector is gone (mapper.hpp: "Replaces `out`").
  sonomap::test::Scene scene;
  scene.boxes.push_back({Eigen::Vector3d(2.0, -1.5, 0.0), Eigen::Vector3d(2.2, 1.5, 2.0)});
  const Eigen::Vector3d eye(0.0, 0.0, 1.5);
  const Eigen::Isometry3d camera = sonomap::test::look_at(eye, Eigen::Vector3d(2.0, 0.0, 1.2));
  const Eigen::Vector3f stale(-50.0f, -50.0f, -50.0f);
  for (const std::string name : {"vdb_gpdf", "tsdf", "open3d", "depth_only"}) {
    INFO(name);
    const auto mapper = make_mapper(name, 0.05, {});
    for (int i = 0; i < 3; ++i) mapper->integrate(sonomap::test::render(scene, camera, i));
    std::vector<Eigen::Vector3f> out{stale};
    mapper->surface_points(eye, 5.0, out);
    const size_t first = out.size();
    CHECK(first > 100);
    CHECK(std::find(out.begin(), out.end(), stale) == out.end());
    mapper->surface_points(eye, 5.0, out);
    CHECK(out.size() == first);
  }
}
