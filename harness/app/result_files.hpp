// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces of a result directory (run.hpp) that every producer of one writes the same way, so
// `report`, `compare` and `diff` read a scored folder (score.hpp) exactly like a run's.
#pragma once

#include "core/raster.hpp"
#include "eval/metrics.hpp"
#include "harness/formats/run_summary.hpp"  // metrics_json, config_hash

#include <Eigen/Geometry>

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace sonomap::harness {

// summary.json's {"final": last frame's metrics, "mean": coverage, rmse, rmse_off_edges and
// ghosts averaged over the frames where each is defined}.
nlohmann::json metrics_summary(const std::vector<eval::RasterMetrics>& frames);

// A range for CSV: empty when unknown; fixed precision so reruns compare byte for byte.
std::string csv_range(const RasterCell& cell);

// circle.csv / cylinder.csv rows of one frame: estimate beside truth.
void write_circle_rows(std::ostream& out, int frame, const Circle& estimate, const Circle& truth);
void write_cylinder_rows(std::ostream& out, int frame, const Cylinder& estimate, const Cylinder& truth);

// frames.csv's header line (with its newline); pose columns of a row (x,y,z,heading_deg).
std::string frames_csv_header();
std::string pose_csv(const Eigen::Isometry3d& world_T_body);

// "key=value" labels as summary.json's "tags" object; InputError naming a malformed one.
nlohmann::json tags_json(const std::vector<std::string>& tags);


}  // namespace sonomap::harness
