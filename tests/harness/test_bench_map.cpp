// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap bench map` end to end on the smoke scene: every mapper has every stage timed, the
// Open3D reference surface lies where our TSDF's does (an independent implementation, same
// frames), bad input exits 2 writing nothing, and the vectorised loops asked for are the ones
// timed. No timing is asserted.
#include "cli_support.hpp"
#include "test_scenario_files.hpp"

#include "core/vector_isa.hpp"

#include <nlohmann/json.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

namespace fs = std::filesystem;
using nlohmann::json;
using sonomap::test::run_sonomap;

namespace {

std::vector<std::string> bench_map_arguments(const fs::path& json_file) {
  return {"-q", "bench", "map", sonomap::test::shipped("scenes/smoke.yaml").string(), "--frames", "3",
          "--voxels", "0.1", "--threads-list", "1", "--json", json_file.string()};
}

}  // namespace

TEST_CASE("bench map times every stage of every mapper and Open3D's surface agrees with the TSDF's",
          "[cli][bench]") {
  const sonomap::test::ScratchDir scratch("bench-map");
  const fs::path file = scratch.path() / "bench.json";
  const auto result = run_sonomap(bench_map_arguments(file));
  INFO(result.output);
  REQUIRE(result.status == 0);
  const json bench = json::parse(sonomap::test::text_of(file));

  // The issue's stages: VDB-GPDF's own, the rasters of our maps, and the whole frame.
  const std::map<std::string, std::set<std::string>> expected{
      {"vdb_gpdf", {"local_gps", "query_points", "fusion", "g_gpdf", "raster", "map", "frame"}},
      {"tsdf", {"raster", "map", "frame"}},
      {"open3d", {"convert", "integrate", "raster", "map", "frame"}}};
  std::set<std::string> seen;
  for (const json& row : bench.at("results")) {
    const std::string mapper = row.at("mapper");
    INFO("mapper " << mapper);
    seen.insert(mapper);
    CHECK(row.at("voxel").get<double>() == Approx(0.1));
    CHECK(row.at("threads").get<int>() == 1);
    CHECK(row.at("frames").get<int>() == 3);
    CHECK(row.at("peak_map_bytes").get<double>() > 0);
    for (const std::string& stage : expected.at(mapper)) CHECK(row.at("median_ms").contains(stage));
    for (const auto& [stage, ms] : row.at("median_ms").items()) {
      INFO("stage " << stage);
      CHECK(std::isfinite(ms.get<double>()));
      CHECK(ms.get<double>() > 0.0);
      // Every timed frame's time is kept, and the median is the middle one of the three.
      auto samples = row.at("samples_ms").at(stage).get<std::vector<double>>();
      REQUIRE(samples.size() == 3);
      std::sort(samples.begin(), samples.end());
      CHECK(samples[1] == ms.get<double>());
    }
    CHECK(row.at("samples_ms").size() == row.at("median_ms").size());
    CHECK(row.at("frame_cpu_ms").size() == 3);
    // Open3D's fusion is the reference every row is compared with, its own included.
    CHECK(row.at("frame_ratio_to_open3d").get<double>() > 0.0);
    if (mapper == "open3d") CHECK(row.at("map_ratio_to_open3d").get<double>() == 1.0);
  }
  CHECK(seen == std::set<std::string>{"vdb_gpdf", "tsdf", "open3d"});

  // Same frames, same poses, an independent TSDF: Open3D's mesh vertices lie on our TSDF's
  // surface to well within a voxel (a wrong extrinsic or axis convention puts them metres off).
  REQUIRE(bench.at("open3d_checks").size() == 1);
  const json& check = bench.at("open3d_checks")[0];
  CHECK(check.at("open3d_vertices").get<int>() > 1000);
  CHECK(check.at("median_distance_m").get<double>() < 0.1);
  CHECK(bench.at("peak_rss_mb").get<double>() > 0.0);
  // Every group was warmed up on its first frames (the default 10, of the 3 there are).
  CHECK(bench.at("warmup_frames_per_group").get<int>() == 3);
  // The instruction set of the vectorised loops, which the figures depend on.
  CHECK(std::set<std::string>{"baseline", "AVX2", "AVX-512"}.count(bench.at("vector_loops")) == 1);
}

TEST_CASE("bench map reports what a coarser voxel and a second thread change, per mapper", "[cli][bench]") {
  const sonomap::test::ScratchDir scratch("bench-map-scaling");
  const fs::path file = scratch.path() / "bench.json";
  const auto result = run_sonomap({"-q", "bench", "map", sonomap::test::shipped("scenes/smoke.yaml").string(),
                                   "--frames", "2", "--voxels", "0.1,0.2", "--threads-list", "1,2",
                                   "--mappers", "vdb_gpdf,open3d", "--json", file.string()});
  INFO(result.output);
  REQUIRE(result.status == 0);
  const json bench = json::parse(sonomap::test::text_of(file));
  // Per mapper: 0.2 against 0.1 m at 1 and at 2 threads; 2 threads against 1 at each voxel.
  std::set<std::string> scaled, sped_up;
  for (const json& row : bench.at("voxel_scaling")) {
    CHECK(row.at("voxel").get<double>() == Approx(0.1));
    CHECK(row.at("to_voxel").get<double>() == Approx(0.2));
    CHECK(row.at("frame_ratio").get<double>() > 0.0);
    scaled.insert(row.at("mapper").get<std::string>() + "@" + std::to_string(row.at("threads").get<int>()));
  }
  for (const json& row : bench.at("thread_speedup")) {
    CHECK(row.at("threads").get<int>() == 2);
    CHECK(row.at("speedup").get<double>() > 0.0);
    sped_up.insert(row.at("mapper").get<std::string>() + "@" + std::to_string(row.at("voxel").get<double>()));
  }
  CHECK(scaled == std::set<std::string>{"vdb_gpdf@1", "vdb_gpdf@2", "open3d@1", "open3d@2"});
  CHECK(sped_up.size() == 4);
  CHECK(result.output.find("2 threads are") != std::string::npos);
}

TEST_CASE("bench map rejects an unknown mapper, a voxel size <= 0, no frames and a warm-up out of range, writing nothing",
          "[cli][bench]") {
  const sonomap::test::ScratchDir scratch("bench-map-bad");
  const fs::path file = scratch.path() / "bench.json";
  const auto with = [&](const std::string& option, const std::string& value) {
    auto arguments = bench_map_arguments(file);
    const auto it = std::find(arguments.begin(), arguments.end(), option);
    REQUIRE(it != arguments.end());
    *(it + 1) = value;
    return run_sonomap(arguments);
  };
  const auto unknown = [&] {
    auto arguments = bench_map_arguments(file);
    arguments.insert(arguments.end(), {"--mappers", "vdb_gpdf,octomap"});
    return run_sonomap(arguments);
  }();
  CHECK(unknown.status == 2);
  CHECK_THAT(unknown.output, Catch::Contains("octomap"));
  const auto zero_voxel = with("--voxels", "0.1,0");
  CHECK(zero_voxel.status == 2);
  CHECK_THAT(zero_voxel.output, Catch::Contains("--voxels"));
  const auto no_frames = with("--frames", "0");
  CHECK(no_frames.status == 2);
  CHECK_THAT(no_frames.output, Catch::Contains("--frames"));
  for (const std::string warmup : {"-1", "1001"}) {
    auto arguments = bench_map_arguments(file);
    arguments.insert(arguments.end(), {"--warmup", warmup});
    const auto bad_warmup = run_sonomap(arguments);
    CHECK(bad_warmup.status == 2);
    CHECK_THAT(bad_warmup.output, Catch::Contains("--warmup must be in [0, 1000], got " + warmup));
  }
  CHECK(sonomap::test::nothing_written(file));
}

TEST_CASE("bench map times the mappers on clouds and a lidar's rings, and refuses Open3D there",
          "[cli][bench]") {
  const sonomap::test::ScratchDir scratch("bench-map-cloud");
  const auto points_of = [&](const std::vector<std::string>& input) {
    const fs::path file = scratch.path() / ("bench" + std::to_string(input.size()) + ".json");
    auto arguments = bench_map_arguments(file);
    arguments.insert(arguments.end(), {"--mappers", "vdb_gpdf,tsdf"});
    arguments.insert(arguments.end(), input.begin(), input.end());
    const auto result = run_sonomap(arguments);
    INFO(result.output);
    REQUIRE(result.status == 0);
    const json bench = json::parse(sonomap::test::text_of(file));
    for (const json& row : bench.at("results")) CHECK(row.at("median_ms").at("frame").get<double>() > 0.0);
    CHECK(bench.at("results").size() == 2);
    CHECK(bench.at("input").at("kind") == (input.empty() ? "image" : "cloud"));
    return bench.at("input").at("median_points").get<double>();
  };
  const double image = points_of({});
  const double rings = points_of({"--input", "cloud", "--row-step", "18"});
  // Rows 0, 18, ..., 468: 27 of the 480 rows.
  CHECK(rings == Approx(image * 27.0 / 480.0).epsilon(0.1));

  const fs::path refused = scratch.path() / "refused.json";
  auto with_open3d = bench_map_arguments(refused);
  with_open3d.insert(with_open3d.end(), {"--input", "cloud"});
  const auto open3d = run_sonomap(with_open3d);
  CHECK(open3d.status == 2);
  CHECK_THAT(open3d.output, Catch::Contains("open3d") && Catch::Contains("--input cloud"));
  auto image_step = bench_map_arguments(refused);
  image_step.insert(image_step.end(), {"--row-step", "8"});
  const auto step = run_sonomap(image_step);
  CHECK(step.status == 2);
  CHECK_THAT(step.output, Catch::Contains("--row-step"));
  CHECK(sonomap::test::nothing_written(refused));
}

TEST_CASE("bench render and bench map run the vectorised loops asked for, and refuse loops this CPU lacks",
          "[cli][bench]") {
  const sonomap::test::ScratchDir scratch("bench-loops");
  const fs::path file = scratch.path() / "bench.json";

  // The baseline loops run on every CPU, and each benchmark says which loops it timed.
  const auto render = run_sonomap({"-q", "bench", "render", "--frames", "1", "--vector-loops", "baseline"});
  INFO(render.output);
  CHECK(render.status == 0);
  CHECK_THAT(render.output, Catch::Contains("baseline loops"));
  auto arguments = bench_map_arguments(file);
  arguments.insert(arguments.end(), {"--mappers", "vdb_gpdf", "--vector-loops", "baseline"});
  const auto map = run_sonomap(arguments);
  INFO(map.output);
  REQUIRE(map.status == 0);
  CHECK(json::parse(sonomap::test::text_of(file)).at("vector_loops") == "baseline");

  // AVX-512 where the CPU has it; elsewhere exit 2, naming what is missing, and no file.
  const fs::path wide = scratch.path() / "avx512.json";
  arguments = bench_map_arguments(wide);
  arguments.insert(arguments.end(), {"--mappers", "vdb_gpdf", "--vector-loops", "avx512"});
  const auto avx512 = run_sonomap(arguments);
  if (sonomap::supported(sonomap::VectorIsa::Avx512)) {
    CHECK(avx512.status == 0);
    CHECK(json::parse(sonomap::test::text_of(wide)).at("vector_loops") == "AVX-512");
  } else {
    CHECK(avx512.status == 2);
    CHECK_THAT(avx512.output, Catch::Contains("--vector-loops avx512: this CPU lacks AVX-512"));
    CHECK(sonomap::test::nothing_written(wide));
  }

  // A name that is no set of loops is bad input.
  const auto unknown = run_sonomap({"-q", "bench", "render", "--frames", "1", "--vector-loops", "sse9"});
  CHECK(unknown.status == 2);
  CHECK_THAT(unknown.output, Catch::Contains("--vector-loops"));
}
