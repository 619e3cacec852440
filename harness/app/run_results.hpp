// SPDX-License-Identifier: GPL-3.0-or-later
// The files of a result directory (docs/results.md): the per-frame rows as the run goes
// (frames.csv, circle.csv, cylinder.csv, timings.csv), the final frame's EDF comparison
// (edf.csv), and at the end summary.json, timings.json and map.ply. Every file is checked
// when it is closed: a full disk is an error, not a truncated result. `score` writes its
// frames.csv, circle.csv and cylinder.csv with the same writers, so `report`, `compare` and
// `diff` read a scored folder exactly like a run's.
#pragma once

#include "core/edf_raster.hpp"
#include "core/mapper.hpp"
#include "core/raster.hpp"
#include "eval/evaluate_frame.hpp"
#include "harness/formats/run_summary.hpp"

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sonomap::harness {

// Wall time of a frame's stages in milliseconds, in the order they ran.
using FrameTimes = std::vector<std::pair<std::string, double>>;

// An output file whose writes are all checked at close().
class ResultFile {
 public:
  explicit ResultFile(std::filesystem::path path);
  template <typename T>
  ResultFile& operator<<(const T& value) {
    out_ << value;
    return *this;
  }
  std::ostream& stream() { return out_; }
  // Throws std::runtime_error naming the file if any write failed.
  void close();

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

// Writes `text` to `path`, checked.
void write_result_file(const std::filesystem::path& path, const std::string& text);

// "key=value" labels (--tag) as summary.json's "tags"; InputError naming a malformed one.
std::map<std::string, std::string> parse_tags(const std::vector<std::string>& tags);

// One evaluated frame as the result files, pictures and sweeps see it.
struct FrameView {
  int index = 0;
  double time = 0.0;
  RasterOrigin origin;  // the estimated pose the rasters are centred on
  const Circle* circle = nullptr;
  const Cylinder* cylinder = nullptr;
  const std::vector<Eigen::Vector3f>* surface = nullptr;  // the band's samples (--video only)
  const Mapper* map = nullptr;  // the map itself (a sweep measures its room from the whole surface)
  const eval::FrameEvaluation* evaluation = nullptr;
};

// One evaluated frame's row of frames.csv: the true pose and each raster's metrics (NaN and
// empty cells where undefined). frames.csv's header and rows are written in one place.
struct FrameRow {
  int frame = 0;
  double time = 0.0;
  Eigen::Isometry3d world_T_body_true = Eigen::Isometry3d::Identity();
  bool has_truth = false;
  eval::RasterMetrics circle;
  std::optional<eval::RasterMetrics> cylinder;    // empty cells: no cylinder (score without one)
  std::optional<eval::RasterMetrics> edf_circle;  // frames with the EDF comparison
  SlipStats slip;
  std::optional<int> moved_ghosts;  // ghost bins reading a place a moving object has left
  static FrameRow of(int frame, double time, const Eigen::Isometry3d& world_T_body_true,
                     const eval::FrameEvaluation& evaluation);
};

// frames.csv's header line and one row (each with its newline).
std::string frames_csv_header();
std::string frames_csv_row(const FrameRow& row);

// circle.csv / cylinder.csv: header lines, and the rows of one frame, estimate beside truth.
inline constexpr const char* kCircleCsvHeader = "frame,bin,estimate,truth\n";
inline constexpr const char* kCylinderCsvHeader = "frame,row,bin,estimate,truth\n";
void write_circle_rows(std::ostream& out, int frame, const Circle& estimate, const Circle& truth);
void write_cylinder_rows(std::ostream& out, int frame, const Cylinder& estimate, const Cylinder& truth);

// The result files written as the run goes, and the metric series the summary is made of.
class RunResults {
 public:
  RunResults(const std::filesystem::path& dir, bool write_rasters);

  // An evaluated frame: its row of frames.csv, its cells in circle.csv and cylinder.csv
  // (unless the run was asked not to write them) and, for the last frame, edf.csv.
  void add_frame(const FrameView& frame, const Eigen::Isometry3d& world_T_body_true, bool last);
  void add_timings(int frame, const FrameTimes& times);

  // The metrics part of the summary, from the frames added so far.
  void fill_metrics(RunSummary& summary, bool edf_enabled) const;
  int evaluated_frames() const { return evaluated_; }

  // Closes the per-frame files and writes summary.json, timings.json and the map's mesh.
  void finish(const RunSummary& summary, const Mapper& mapper);

 private:
  void add_row(const FrameRow& row);
  void add_rasters(const FrameView& frame);
  std::filesystem::path dir_;
  ResultFile frames_, timings_;
  std::optional<ResultFile> circle_, cylinder_;
  int evaluated_ = 0;
  std::vector<eval::RasterMetrics> circle_series_, cylinder_series_, edf_series_;
  std::vector<SlipStats> slip_series_;
  std::vector<std::string> timing_columns_;
  std::map<std::string, std::vector<TimedFrame>> timing_samples_;
  int frames_run_ = 0;
};

// edf.csv: per bin of the frame (the final one), the map's circle next to the EDF's.
void write_edf_csv(const std::filesystem::path& file, const FrameView& frame);

}  // namespace sonomap::harness
