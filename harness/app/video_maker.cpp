// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/video_maker.hpp"

#include "harness/app/run_results.hpp"

#include <fmt/format.h>

#include <cmath>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {

constexpr double kDefaultRateHz = 30.0;  // a one-frame run has no interval to measure
const Rgb kBackground{0x18, 0x18, 0x20}, kTitle{0xc8, 0xc8, 0xd0};
const char* kSilentVideo = "run.video-only.mp4";

std::string metric_line(const char* name, const eval::RasterMetrics& m, bool has_truth) {
  if (!has_truth) return fmt::format("{}: {} CELLS KNOWN (NO TRUTH)", name, m.estimate_known);
  auto number = [](double v, const char* format) {
    return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("-");
  };
  return fmt::format("{}: COVERAGE {}  RMSE {}  GHOSTS {}", name, number(100.0 * m.coverage, "{:.1f}%"),
                     number(m.rmse, "{:.3f} M"), m.ghosts);
}

}  // namespace

int SweepClock::sector_at(double t) const {
  const double cycle = period_s + pause_s;
  if (!(cycle > 0.0) || sectors <= 0 || t < 0.0) return -1;
  const double phase = std::fmod(t, cycle);
  if (phase >= period_s) return -1;
  return std::min(sectors - 1, static_cast<int>(std::floor(phase * sectors / period_s)));
}

RunVideo::RunVideo(fs::path dir, std::string scenario, std::string mapper, RasterConfig raster,
                   int frame_count, SweepClock clock)
    : dir_(std::move(dir)), scenario_(std::move(scenario)), mapper_(std::move(mapper)),
      raster_(raster), frame_count_(frame_count), clock_(clock), circle_(raster.azimuth_bins) {
  require_ffmpeg("--video");
}

RunVideo::~RunVideo() = default;

void RunVideo::add_rasters(const FrameView& view) {
  circle_ = *view.circle;
  circle_metrics_ = view.evaluation->circle;
  cylinder_metrics_ = view.evaluation->cylinder;
  has_truth_ = view.evaluation->has_truth;
  rasters_frame_ = view.index;
  top_view_.add_surface(*view.surface, view.origin.ground_z + raster_.band_min,
                        view.origin.ground_z + raster_.band_max);
}

Canvas RunVideo::draw(const Frame& frame) const {
  Canvas canvas(kWidth, kHeight, kBackground);
  const int w = kWidth / 2, h = kHeight / 2, title = 24;
  draw_depth(canvas, {0, title, w, h - title}, frame, raster_.max_range);
  const int sector = clock_.sector_at(frame.time - start_time_);
  draw_circle(canvas, {w, title, w, h - title}, circle_, raster_, sector, clock_.sectors);
  top_view_.draw(canvas, {0, h + title, w, h - title});
  canvas.text(8, 4, "DEPTH IMAGE", kTitle);
  canvas.text(w + 8, 4, "CIRCLE, AHEAD UP (YELLOW: SECTOR PLAYING)", kTitle);
  canvas.text(8, h + 4, "MAP FROM ABOVE, NORTH UP, AND THE PATH", kTitle);
  std::vector<std::string> lines{
      fmt::format("{} / {}", scenario_, mapper_),
      fmt::format("FRAME {} OF 0-{}   T = {:.2f} S", frame.index, frame_count_ - 1, frame.time),
      sector < 0 ? std::string("SWEEP: PAUSE")
                 : fmt::format("SWEEP: SECTOR {} ({}-{} DEG LEFT OF AHEAD)", sector,
                               sector * 360 / clock_.sectors, (sector + 1) * 360 / clock_.sectors)};
  if (rasters_frame_ >= 0) {
    lines.push_back(fmt::format("METRICS OF FRAME {}", rasters_frame_));
    lines.push_back(metric_line("CIRCLE", circle_metrics_, has_truth_));
    lines.push_back(metric_line("CYLINDER", cylinder_metrics_, has_truth_));
  }
  draw_lines(canvas, {w, h, w, h}, lines);
  return canvas;
}

void RunVideo::add_frame(const Frame& frame) {
  if (!started_) start_time_ = frame.time;  // the sound track's time 0
  started_ = true;
  const Eigen::Vector3d p = frame.world_T_body.translation();
  const Eigen::Vector3d ahead = frame.world_T_body.linear().col(0);
  top_view_.add_pose(p.head<2>(), std::atan2(ahead.y(), ahead.x()));
  encode(draw(frame), frame.time);
}

void RunVideo::encode(const Canvas& picture, double time) {
  if (!encoder_ && !first_) {
    first_ = picture;
    first_time_ = time;
    return;
  }
  if (!encoder_) {
    const double interval = time - first_time_;
    rate_hz_ = interval > 0.0 && std::isfinite(interval) ? 1.0 / interval : kDefaultRateHz;
    encoder_ = std::make_unique<VideoEncoder>(dir_ / kSilentVideo, kWidth, kHeight, rate_hz_);
    encoder_->add(*first_);
    first_.reset();
  }
  encoder_->add(picture);
}

void RunVideo::finish(const std::optional<fs::path>& audio) {
  if (!encoder_ && !first_) return;
  if (!encoder_) {  // a one-frame run
    rate_hz_ = kDefaultRateHz;
    encoder_ = std::make_unique<VideoEncoder>(dir_ / kSilentVideo, kWidth, kHeight, rate_hz_);
    encoder_->add(*first_);
    first_.reset();
  }
  encoder_->finish();
  const fs::path silent = dir_ / kSilentVideo, out = dir_ / "run.mp4";
  if (audio) {
    add_sound_track(silent, *audio, encoder_->frames() / rate_hz_, out);
    fs::remove(silent);
  } else {
    fs::rename(silent, out);
  }
}

}  // namespace sonomap::harness
