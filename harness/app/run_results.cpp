// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/run_results.hpp"

#include "core/types.hpp"
#include "harness/formats/mesh_io.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

std::string csv_number(double v) { return std::isfinite(v) ? fmt::format("{:.6f}", v) : ""; }

// A range for CSV: empty when unknown; fixed precision so reruns compare byte for byte.
std::string csv_range(const RasterCell& cell) {
  return cell.known() ? fmt::format("{:.6f}", cell.range) : std::string();
}

// coverage,rmse,rmse_off_edges,ghosts,known (ghosts empty without truth; all empty without
// the raster).
std::string metrics_csv(const std::optional<eval::RasterMetrics>& m, bool has_truth) {
  if (!m) return ",,,,";
  return csv_number(m->coverage) + ',' + csv_number(m->rmse) + ',' + csv_number(m->rmse_off_edges) +
         ',' + (has_truth ? std::to_string(m->ghosts) : "") + ',' + std::to_string(m->estimate_known);
}

// x,y,z,heading_deg of a pose.
std::string pose_csv(const Eigen::Isometry3d& world_T_body) {
  const Eigen::Vector3d p = world_T_body.translation();
  return fmt::format("{:.6f},{:.6f},{:.6f},{:.4f}", p.x(), p.y(), p.z(),
                     heading_of(world_T_body) * 180.0 / M_PI);
}

}  // namespace

std::string frames_csv_header() {
  return "frame,time,x,y,z,heading_deg,"
         "circle_coverage,circle_rmse,circle_rmse_off_edges,circle_ghosts,circle_known,"
         "cylinder_coverage,cylinder_rmse,cylinder_rmse_off_edges,cylinder_ghosts,"
         "cylinder_known,edf_coverage,edf_rmse,edf_rmse_off_edges,edf_ghosts,edf_known,"
         "edf_slip_median_deg,edf_slip_p90_deg,edf_slip_known,circle_moved_ghosts\n";
}

std::string frames_csv_row(const FrameRow& r) {
  std::string line = fmt::format("{},{:.6f},", r.frame, r.time) + pose_csv(r.world_T_body_true) +
                     ',' + metrics_csv(r.circle, r.has_truth) + ',' +
                     metrics_csv(r.cylinder, r.has_truth);
  if (r.edf_circle)
    line += ',' + metrics_csv(r.edf_circle, r.has_truth) + ',' + csv_number(r.slip.median_deg) +
            ',' + csv_number(r.slip.p90_deg) + ',' + std::to_string(r.slip.observed);
  else
    line += ",,,,,,,,";
  line += ',' + (r.moved_ghosts ? std::to_string(*r.moved_ghosts) : std::string());
  return line + '\n';
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

std::map<std::string, std::string> parse_tags(const std::vector<std::string>& tags) {
  std::map<std::string, std::string> out;
  for (const std::string& t : tags) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--tag " + t + ": expected key=value");
    out[t.substr(0, eq)] = t.substr(eq + 1);
  }
  return out;
}

ResultFile::ResultFile(fs::path path) : path_(std::move(path)), out_(path_) {}

void ResultFile::close() {
  if (out_.is_open()) close_checked(out_, path_);
}

void write_result_file(const fs::path& path, const std::string& text) {
  ResultFile file(path);
  file << text;
  file.close();
}

FrameRow FrameRow::of(int frame, double time, const Eigen::Isometry3d& world_T_body_true,
                      const eval::FrameEvaluation& evaluation) {
  FrameRow row{frame, time, world_T_body_true, evaluation.has_truth, evaluation.circle,
               evaluation.cylinder, std::nullopt, evaluation.slip, std::nullopt};
  if (evaluation.edf) row.edf_circle = evaluation.edf_circle;
  if (evaluation.moved) row.moved_ghosts = evaluation.moved->bins;
  return row;
}

RunResults::RunResults(const fs::path& dir, bool write_rasters)
    : dir_(dir), frames_(dir / "frames.csv"), timings_(dir / "timings.csv") {
  frames_ << frames_csv_header();
  if (write_rasters) {
    circle_.emplace(dir / "circle.csv");
    cylinder_.emplace(dir / "cylinder.csv");
    *circle_ << kCircleCsvHeader;
    *cylinder_ << kCylinderCsvHeader;
  }
}

void RunResults::add_frame(const FrameView& frame, const Eigen::Isometry3d& world_T_body_true,
                           bool last) {
  const eval::FrameEvaluation& e = *frame.evaluation;
  add_row(FrameRow::of(frame.index, frame.time, world_T_body_true, e));
  add_rasters(frame);
  if (last && e.edf) write_edf_csv(dir_ / "edf.csv", frame);
}

void RunResults::add_row(const FrameRow& row) {
  ++evaluated_;
  if (row.has_truth) {
    circle_series_.push_back(row.circle);
    cylinder_series_.push_back(*row.cylinder);
    if (row.edf_circle) edf_series_.push_back(*row.edf_circle);
  }
  if (row.edf_circle) slip_series_.push_back(row.slip);
  frames_ << frames_csv_row(row);
}

void RunResults::add_rasters(const FrameView& f) {
  if (!circle_) return;
  write_circle_rows(circle_->stream(), f.index, *f.circle, f.evaluation->truth.circle);
  write_cylinder_rows(cylinder_->stream(), f.index, *f.cylinder, f.evaluation->truth.cylinder);
}

// The columns are the stages of the first frame (every frame has them; evaluated frames more).
void RunResults::add_timings(int frame, const FrameTimes& times) {
  if (timing_columns_.empty()) {
    for (const auto& t : times) timing_columns_.push_back(t.first);
    timings_ << "frame";
    for (const auto& name : timing_columns_) timings_ << ',' << name << "_ms";
    timings_ << '\n';
  }
  timings_ << frame;
  for (const auto& name : timing_columns_) {
    auto it = std::find_if(times.begin(), times.end(), [&](auto& t) { return t.first == name; });
    timings_ << ',' << (it != times.end() ? fmt::format("{:.3f}", it->second) : "");
    if (it != times.end()) timing_samples_[name].push_back({frame, it->second});
  }
  timings_ << '\n';
  frames_run_ = std::max(frames_run_, frame + 1);
}

void RunResults::fill_metrics(RunSummary& summary, bool edf_enabled) const {
  summary.evaluated_frames = evaluated_;
  summary.circle = RasterSummary::of(circle_series_);
  summary.cylinder = RasterSummary::of(cylinder_series_);
  if (edf_enabled) {
    summary.edf_circle = RasterSummary::of(edf_series_);
    summary.edf = EdfSummary::of(slip_series_);
  }
}

void RunResults::finish(const RunSummary& summary, const Mapper& mapper) {
  for (ResultFile* f : {&frames_, &timings_}) f->close();
  for (auto* f : {&circle_, &cylinder_})
    if (*f) (*f)->close();
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  mapper.surface_mesh(vertices, triangles);
  if (!triangles.empty()) save_mesh_ply(dir_ / "map.ply", vertices, triangles);
  write_result_file(dir_ / "summary.json", nlohmann::json(summary).dump(2) + "\n");
  write_result_file(dir_ / "timings.json",
                    nlohmann::json(summarise_timings(timing_samples_, frames_run_)).dump(2) + "\n");
}

void write_edf_csv(const fs::path& file, const FrameView& f) {
  const Circle& map_circle = *f.circle;
  const EdfRaster& edf = *f.evaluation->edf;
  const Circle& truth = f.evaluation->truth.circle;
  const double ground_z = f.origin.ground_z;
  const int frame = f.index;
  ResultFile out(file);
  out << "frame,bin,azimuth_deg,map_range,edf_distance,slip_deg,traced_range,traced_height,truth,"
         "trace_end\n";
  for (int k = 0; k < map_circle.size(); ++k) {
    const EdfBin& b = edf.bins[k];
    out << frame << ',' << k << ',' << fmt::format("{:.4f}", map_circle.bin_centre_deg(k)) << ','
        << csv_range(map_circle.bins[k]) << ',' << csv_number(b.sample_distance) << ','
        << csv_number(b.slip_deg) << ',' << csv_range(edf.traced.bins[k]) << ','
        << csv_number(edf.traced.bins[k].point.z() - ground_z) << ',' << csv_range(truth.bins[k])
        << ',' << trace_end_name(b.end) << '\n';
  }
  out.close();
}

}  // namespace sonomap::harness
