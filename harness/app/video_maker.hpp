// SPDX-License-Identifier: GPL-3.0-or-later
// run.mp4 (`run --video`): one picture per sensor frame, at the sensor's rate, so the video
// lasts as long as the run. Each picture shows the simulated depth image, the circle around
// the listener with the sector the sweep plays at that moment, the map from above with the
// path walked so far, and the frame's time and latest metrics. The sound track is a WAV
// given at the end (the listening stream), padded or cut to the run's duration.
#pragma once

#include "core/raster.hpp"
#include "core/types.hpp"
#include "eval/metrics.hpp"
#include "harness/app/video_canvas.hpp"
#include "harness/app/video_encoder.hpp"
#include "harness/app/video_panels.hpp"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace sonomap::harness {

struct FrameView;

// Which sector the sweep plays when: sweeps start every period_s + pause_s from the run's first
// frame (t = 0), and sector s starts s * period_s / sectors into its sweep (audio/sweep.hpp's
// default onsets).
struct SweepClock {
  double period_s = 2.0;
  double pause_s = 0.0;
  int sectors = 36;
  int sector_at(double t) const;  // -1 during a pause
};

class RunVideo {
 public:
  static constexpr int kWidth = 1280, kHeight = 720;
  // Throws InputError naming ffmpeg when it is not installed.
  RunVideo(std::filesystem::path dir, std::string scenario, std::string mapper,
           RasterConfig raster, int frame_count, SweepClock clock);
  ~RunVideo();
  // An evaluated frame's rasters, map samples and metrics: shown until the next one.
  void add_rasters(const FrameView& view);
  // Every frame, after add_rasters when it was evaluated: draws and encodes its picture.
  void add_frame(const Frame& frame);
  // dir/run.mp4, with `audio` as its sound track when given. Throws if ffmpeg failed.
  void finish(const std::optional<std::filesystem::path>& audio);

  // The picture of `frame` (no encoding): for tests and stills.
  Canvas draw(const Frame& frame) const;

 private:
  void encode(const Canvas& picture, double time);
  std::filesystem::path dir_;
  std::string scenario_, mapper_;
  RasterConfig raster_;
  int frame_count_;
  SweepClock clock_;
  Circle circle_;
  eval::RasterMetrics circle_metrics_, cylinder_metrics_;
  bool has_truth_ = false;
  int rasters_frame_ = -1;
  TopView top_view_;
  bool started_ = false;
  double start_time_ = 0.0;  // the first frame's
  std::optional<Canvas> first_;  // held until the second frame gives the rate
  double first_time_ = 0.0, rate_hz_ = 0.0;
  std::unique_ptr<VideoEncoder> encoder_;
};

}  // namespace sonomap::harness
