// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/listen_step.hpp"

#include "harness/app/run_results.hpp"
#include "harness/app/sonify.hpp"
#include "harness/formats/wav_io.hpp"
#include "harness/support/errors.hpp"

#include <fmt/format.h>

#include <cmath>

namespace fs = std::filesystem;

namespace sonomap::harness {

double run_duration(double first_time, double last_time, int frame_count) {
  if (frame_count < 2 || !(last_time > first_time)) return 1.0 / 30.0;
  const double span = last_time - first_time;
  return span + span / (frame_count - 1);
}

ListenStep::ListenStep(fs::path dir, const RunOptions& options, const ListenSettings& settings,
                       std::optional<sim::HeadSpec> head)
    : dir_(std::move(dir)), settings_(settings), head_(std::move(head)) {
  SonifySetup setup;
  setup.brir_dir = options.brir_dir;
  setup.room.rt60 = settings.rt60;
  setup.sweep.woosh_unknown = settings.woosh;
  try {
    stream_ = std::make_unique<audio::ListenStream>(load_brirs(setup, options.quiet), setup.sweep,
                                                    settings.stream);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--listen: ") + e.what());
  }
}

ListenStep::~ListenStep() = default;

double ListenStep::head_yaw_deg(double t, double body_yaw_deg) const {
  if (!head_) return body_yaw_deg;
  const double yaw = head_->at(t).yaw_deg;
  return head_->absolute ? yaw : body_yaw_deg + yaw;
}

void ListenStep::play_until(double stream_time) {
  if (!circle_) return;
  const double body_yaw = body_yaw_deg_;
  const double offset = first_time_;
  stream_->play(*circle_, circle_time_, stream_time, body_yaw,
                [&](double t) { return head_yaw_deg(t + offset, body_yaw); });
}

void ListenStep::add(const FrameView& frame) {
  if (!circle_) first_time_ = frame.time;
  const double t = frame.time - first_time_;
  play_until(t);
  circle_ = *frame.circle;
  circle_time_ = t;
  body_yaw_deg_ = frame.origin.heading * 180.0 / M_PI;
}

ListenSummary ListenStep::finish(int frame_count) {
  const double duration = run_duration(0.0, circle_time_, frame_count);
  play_until(duration);
  const audio::ListenAudio audio = stream_->finish(duration);
  const audio::TapLocalisation where = audio::localise_taps(audio, stream_->renderer());
  write_wav(dir_ / kListenWav, audio.sample_rate, audio.left, audio.right);
  write_result_file(dir_ / kListenEvents, listen_events_csv(audio, where));
  ListenSummary s;
  s.file = kListenWav;
  s.mode = audio::to_string(settings_.stream.mode);
  s.duration_s = static_cast<double>(audio.left.size()) / audio.sample_rate;
  s.taps = static_cast<int>(audio.taps.size());
  s.gain_db = audio.gain_db;
  s.loudness_lufs = audio.loudness.integrated_lufs;
  s.true_peak_dbtp = audio.loudness.true_peak_dbtp;
  s.peak_limited = audio.peak_limited;
  s.localised_taps = where.taps;
  s.median_error_deg = where.median_error_deg;
  s.p90_error_deg = where.p90_error_deg;
  return s;
}

namespace {
const char* const kListenHeader =
    "time_s,sweep,sector,body_azimuth_deg,world_azimuth_deg,head_yaw_deg,head_azimuth_deg,"
    "range_m,brir_distance_m,brir_azimuth_deg,pitch_semitones,sound,level_dbfs,"
    "heard_azimuth_deg,gain_db,loudness_lufs";

std::string cell(double v) { return std::isfinite(v) ? fmt::format("{:.3f}", v) : std::string(); }
}  // namespace

std::string listen_events_csv(const audio::ListenAudio& audio, const audio::TapLocalisation& where) {
  std::string text = std::string(kListenHeader) + "\n";
  for (size_t i = 0; i < audio.taps.size(); ++i) {
    const audio::ListenTap& t = audio.taps[i];
    text += fmt::format("{:.6f},{},{},{},{},{},{},{},{:.1f},{},{:+.0f},{},{},{},{},{}\n", t.time_s,
                        t.sweep, t.sector, cell(t.body_azimuth_deg), cell(t.world_azimuth_deg),
                        cell(t.head_yaw_deg), cell(t.head_azimuth_deg), cell(t.range_m),
                        t.brir_distance_m, cell(t.brir_azimuth_deg), t.pitch_semitones,
                        audio::to_string(t.sound), cell(t.level_dbfs),
                        i < where.estimated_azimuth_deg.size() ? cell(where.estimated_azimuth_deg[i]) : "",
                        cell(audio.gain_db), cell(audio.loudness.integrated_lufs));
  }
  return text;
}

}  // namespace sonomap::harness
