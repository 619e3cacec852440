// SPDX-License-Identifier: GPL-3.0-or-later
// Harness side of the sonification: command-line options for the room and the sweep, loading
// or synthesising the BRIR set, and writing a sweep (WAV + event CSV, atomically). Used by
// `sonomap sonify` and `sonomap brir`, and by a run that renders sweeps for chosen frames:
//
//   auto brirs = load_brirs(setup, quiet);                 // once
//   audio::SweepRenderer renderer(brirs, setup.sweep);     // once (spectra cached inside)
//   write_sweep(renderer.render(circle), dir / "sweep_000042.wav");
#pragma once

#include "audio/brir_synth.hpp"
#include "audio/sweep.hpp"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace sonomap::harness {

// The HRIR set BRIRs are synthesised from unless --hrir says otherwise (MIT KEMAR, Debian).
std::filesystem::path default_hrir_file();

// Room options as typed; resolved (and checked) by room_config().
struct RoomOptions {
  std::string room = "5x4x3";  // L x W x H metres, corner at the origin
  std::vector<double> room_min, room_max;  // or two corners (e.g. a map's bounding box)
  std::vector<double> listener;            // x,y,z; empty: room centre at 1.5 m
  double heading_deg = 0.0;
  double rt60 = 0.5;
  int order = 3;
  double length_s = 0.0;  // 0: the RT60
  unsigned long long seed = 1;
  std::filesystem::path hrir_file = default_hrir_file();
};
void add_room_options(CLI::App& command, RoomOptions& options);
// InputError naming the option on a bad value.
audio::BrirSynthConfig room_config(const RoomOptions& options, double sample_rate);

// A room from a bounding box (e.g. of a map), with the listener at `listener`.
audio::BrirSynthConfig room_from_box(const Eigen::Vector3d& min_corner,
                                     const Eigen::Vector3d& max_corner,
                                     const Eigen::Vector3d& listener, double rt60);

// Synthesises the paper's grid for a room (progress on stderr unless quiet), normalised to the
// reference level. on_demand: each point is kept only once it is looked up (sweeps play a few
// dozen of the 1200); otherwise every point is held (to write them all).
audio::BrirSet synthesize_brirs(const audio::BrirSynthConfig& room,
                                const std::filesystem::path& hrir_file, bool quiet, bool on_demand);

struct SonifySetup {
  std::filesystem::path brir_dir;  // empty: synthesise the room below in memory
  RoomOptions room;
  audio::SweepConfig sweep;
};
// Adds --brir, the room options and the sweep options (mode, period, filters, pitch ...).
void add_sonify_options(CLI::App& command, SonifySetup& setup);
// Checks the sweep options; InputError naming the option.
void check_sweep_options(const SonifySetup& setup);
// Loads the BRIR directory (resampled to the sweep rate), or synthesises the default room
// (and says so on stderr unless quiet).
std::shared_ptr<const audio::BrirSet> load_brirs(const SonifySetup& setup, bool quiet);

// The event log: time_s,sector,azimuth_deg,range_m,brir_distance_m,brir_azimuth_deg,
// pitch_semitones,sound (range empty for a woosh), then the file's level on every row:
// gain_db (the one gain applied), loudness_lufs (integrated, EBU R128; -inf when too short or
// silent) and true_peak_dbtp (4x oversampled), both measured on the written signal.
std::string sweep_events_csv(const audio::SweepAudio& audio);
// "sweep.wav" -> "sweep.events.csv"
std::filesystem::path events_path_for(const std::filesystem::path& wav);
// A sweep sonomap wrote (the WAV or its event CSV): the event CSV starts with the event log's
// header. Only such files are replaced by a new sweep (docs/outputs.md).
bool is_sonomap_sweep(const std::filesystem::path& file);
// The output checks of a sweep (WAV and event CSV), before the work: InputError if either
// exists and is not a sweep sonomap wrote, or is an input.
void check_sweep_output(const std::filesystem::path& wav,
                        const std::vector<std::filesystem::path>& inputs);
// Writes the WAV and its event CSV, each staged and renamed: no partial files on failure.
// audio.gain_db / audio.loudness are the figures a run's summary carries.
void write_sweep(const audio::SweepAudio& audio, const std::filesystem::path& wav);

}  // namespace sonomap::harness
