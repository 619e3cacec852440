// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/result_files.hpp"

#include "core/types.hpp"
#include "harness/support/errors.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>

using nlohmann::json;

namespace sonomap::harness {

json metrics_summary(const std::vector<eval::RasterMetrics>& frames) {
  return raster_summary_json(RasterSummary::of(frames));
}

std::string csv_range(const RasterCell& cell) {
  return cell.known() ? fmt::format("{:.6f}", cell.range) : std::string();
}

void write_circle_rows(std::ostream& out, int frame, const Circle& estimate, const Circle& truth) {
  for (int k = 0; k < estimate.size(); ++k)
    out << frame << ',' << k << ',' << csv_range(estimate.bins[k]) << ',' << csv_range(truth.bins[k]) << '\n';
}

void write_cylinder_rows(std::ostream& out, int frame, const Cylinder& estimate, const Cylinder& truth) {
  for (int r = 0; r < estimate.rows; ++r)
    for (int k = 0; k < estimate.azimuth_bins; ++k)
      out << frame << ',' << r << ',' << k << ',' << csv_range(estimate.at(r, k)) << ','
          << csv_range(truth.at(r, k)) << '\n';
}

std::string frames_csv_header() {
  return "frame,time,x,y,z,heading_deg,"
         "circle_coverage,circle_rmse,circle_rmse_off_edges,circle_ghosts,circle_known,"
         "cylinder_coverage,cylinder_rmse,cylinder_rmse_off_edges,cylinder_ghosts,"
         "cylinder_known,edf_coverage,edf_rmse,edf_rmse_off_edges,edf_ghosts,edf_known,"
         "edf_slip_median_deg,edf_slip_p90_deg,edf_slip_known\n";
}

std::string pose_csv(const Eigen::Isometry3d& world_T_body) {
  const Eigen::Vector3d p = world_T_body.translation();
  return fmt::format("{:.6f},{:.6f},{:.6f},{:.4f}", p.x(), p.y(), p.z(),
                     heading_of(world_T_body) * 180.0 / M_PI);
}

json tags_json(const std::vector<std::string>& tags) {
  json out = json::object();
  for (const std::string& t : tags) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--tag " + t + ": expected key=value");
    out[t.substr(0, eq)] = t.substr(eq + 1);
  }
  return out;
}

}  // namespace sonomap::harness
