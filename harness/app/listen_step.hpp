// SPDX-License-Identifier: GPL-3.0-or-later
// The run's listen step (`run --listen`): the binaural stream over the whole run, written as
// listen.wav and listen_events.csv in the result directory (docs/sonification.md). Streaming:
// it keeps one circle, the latest evaluated frame's, which plays from that frame's time until
// the next evaluated frame replaces it.
//
//   ListenStep listen(dir, options, settings.listen, source.head());
//   for each evaluated frame: listen.add(view);
//   summary.listen = listen.finish(run_duration);   // also what run.mp4's audio track is
#pragma once

#include "audio/listen_stream.hpp"
#include "harness/app/run.hpp"
#include "harness/app/run_results.hpp"
#include "harness/app/run_settings.hpp"

#include <filesystem>
#include <memory>
#include <optional>

namespace sonomap::harness {

// The name of the stream in a run's result directory.
constexpr const char* kListenWav = "listen.wav";
constexpr const char* kListenEvents = "listen_events.csv";

class ListenStep {
 public:
  ListenStep(std::filesystem::path dir, const RunOptions& options, const ListenSettings& settings,
             std::optional<sim::HeadSpec> head);
  ~ListenStep();
  // The frame's circle takes over from the previous one at the frame's time.
  void add(const FrameView& frame);
  // Plays the last circle to the run's end, levels the stream and writes both files.
  // `frame_count`: the frames of the run (the first and last are always evaluated).
  ListenSummary finish(int frame_count);

  // The head's world yaw at time t (degrees) for a body of world yaw body_yaw_deg.
  double head_yaw_deg(double t, double body_yaw_deg) const;

 private:
  void play_until(double stream_time);
  std::filesystem::path dir_;
  ListenSettings settings_;
  std::optional<sim::HeadSpec> head_;
  std::unique_ptr<audio::ListenStream> stream_;
  std::optional<Circle> circle_;  // the latest evaluated frame's
  double first_time_ = 0.0;       // the run's first frame: the stream's time 0
  double circle_time_ = 0.0, body_yaw_deg_ = 0.0;
};

// The run's duration as the stream and the video take it: from the first frame's time (the
// stream's 0) to the last's, plus one mean frame interval (one frame alone: 1 / 30 s).
double run_duration(double first_time, double last_time, int frame_count);

// The event log: one row per tap (header in listen_step.cpp, columns in docs/results.md).
std::string listen_events_csv(const audio::ListenAudio& audio, const audio::TapLocalisation& where);

}  // namespace sonomap::harness
