// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/sonify.hpp"

#include "harness/formats/sofa_io.hpp"
#include "harness/formats/wav_io.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"
#include "harness/support/interrupt.hpp"
#include "harness/support/output.hpp"
#include "harness/support/progress.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace fs = std::filesystem;

namespace sonomap::harness {

fs::path default_hrir_file() { return "/usr/share/libmysofa/default.sofa"; }

// Positions within 10 km of the origin (docs/settings.md, "Bounds").
static const CLI::Range kPositionRange(-kMaxPosition, kMaxPosition);

void add_room_options(CLI::App& cmd, RoomOptions& o) {
  cmd.add_option("--room", o.room, "Shoebox room LxWxH in metres (corner at the origin)");
  cmd.add_option("--room-min", o.room_min, "Room corner x,y,z (with --room-max; e.g. a map's box)")
      ->delimiter(',')->expected(3)->check(kPositionRange);
  cmd.add_option("--room-max", o.room_max, "Opposite room corner x,y,z")
      ->delimiter(',')->expected(3)->check(kPositionRange);
  cmd.add_option("--listener", o.listener, "Head position x,y,z (default: room centre, 1.5 m high)")
      ->delimiter(',')->expected(3)->check(kPositionRange);
  cmd.add_option("--heading", o.heading_deg, "Direction the listener faces, degrees from +x")
      ->check(CLI::Range(-3600.0, 3600.0));
  cmd.add_option("--rt60", o.rt60, "Reverberation time, seconds");
  cmd.add_option("--order", o.order, "Image-source reflection order");
  cmd.add_option("--ir-length", o.length_s, "BRIR length, seconds (0: the RT60)");
  cmd.add_option("--seed", o.seed, "Seed of the late-tail noise")
      ->check(CLI::Range(0ull, static_cast<unsigned long long>(kMaxSeed)));
  cmd.add_option("--hrir", o.hrir_file, "HRIR set (SOFA) the BRIRs are built from");
}

// A room side in metres: a number in (0, kMaxPosition].
static double room_side(const std::string& text) {
  double v = 0.0;
  if (!parse_number(text, v) || !(v > 0.0 && v <= kMaxPosition))
    throw InputError("option --room: expected each side in (0, " + number_text(kMaxPosition) +
                     "] m, got '" + text + "'");
  return v;
}

audio::BrirSynthConfig room_config(const RoomOptions& o, double sample_rate) {
  audio::BrirSynthConfig c;
  if (!o.room_min.empty() || !o.room_max.empty()) {
    if (o.room_min.size() != 3 || o.room_max.size() != 3)
      throw InputError("options --room-min/--room-max: give both, as x,y,z");
    c.room.min_corner = Eigen::Vector3d(o.room_min[0], o.room_min[1], o.room_min[2]);
    c.room.max_corner = Eigen::Vector3d(o.room_max[0], o.room_max[1], o.room_max[2]);
  } else {
    std::vector<double> dims;
    std::stringstream in(o.room);
    std::string part;
    while (std::getline(in, part, 'x')) dims.push_back(room_side(part));
    if (dims.size() != 3)
      throw InputError("option --room: expected LxWxH (e.g. 5x4x3), got '" + o.room + "'");
    c.room.min_corner.setZero();
    c.room.max_corner = Eigen::Vector3d(dims[0], dims[1], dims[2]);
  }
  if (!o.listener.empty()) {
    if (o.listener.size() != 3) throw InputError("option --listener: expected x,y,z");
    c.listener = Eigen::Vector3d(o.listener[0], o.listener[1], o.listener[2]);
  }
  c.listener_heading_deg = o.heading_deg;
  c.rt60 = o.rt60;
  c.max_order = o.order;
  c.length_s = o.length_s;
  c.seed = o.seed;
  c.sample_rate = sample_rate;
  try {
    audio::validate(c);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("room options (--room, --listener, --rt60, --order, --ir-length): ") +
                     e.what());
  }
  return c;
}

audio::BrirSynthConfig room_from_box(const Eigen::Vector3d& min_corner,
                                     const Eigen::Vector3d& max_corner,
                                     const Eigen::Vector3d& listener, double rt60) {
  audio::BrirSynthConfig c;
  c.room.min_corner = min_corner;
  c.room.max_corner = max_corner;
  c.listener = listener;
  c.rt60 = rt60;
  audio::validate(c);
  return c;
}

audio::BrirSet synthesize_brirs(const audio::BrirSynthConfig& room, const fs::path& hrir_file,
                                bool quiet, bool on_demand) {
  auto synth = std::make_shared<const audio::BrirSynthesizer>(read_hrir_set(hrir_file, room.sample_rate), room);
  const audio::BrirGrid grid = audio::BrirGrid::paper();
  try {
    for (double d : grid.distances_m) synth->check_source(0.0, d);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("option --ir-length: ") + e.what());
  }
  const long points = static_cast<long>(grid.azimuths_deg.size() * grid.distances_m.size());
  Progress progress("BRIRs", points, quiet);
  // On demand, a sweep's few dozen points stay in memory (the same responses and level as the
  // whole grid synthesised and normalised, which a writer of every point wants instead).
  // A signal stops the synthesis within one grid point's work (the rest are skipped).
  install_interrupt_handler();
  audio::BrirSet set = on_demand ? audio::BrirSynthesizer::synthesize_on_demand(synth, grid, interrupt_requested)
                                 : synth->synthesize(grid, interrupt_requested);
  throw_if_interrupted();
  if (!on_demand) set.normalise_to_reference();
  progress.update(points);
  progress.finish();
  return set;
}

void add_sonify_options(CLI::App& cmd, SonifySetup& s) {
  cmd.add_option("--brir", s.brir_dir, "Directory of BRIR SOFA files, one per distance "
                                       "(default: synthesise the room given by the room options)");
  add_room_options(cmd, s.room);
  audio::SweepConfig& w = s.sweep;
  cmd.add_option("--mode", w.mode, "ranging (every sector) or objects (pseudo-objects)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, audio::SweepMode>{{"ranging", audio::SweepMode::Ranging},
                                                  {"objects", audio::SweepMode::Objects}}));
  cmd.add_option("--period", w.period_s, "Seconds per sweep (36 sectors)");
  cmd.add_option("--sector-onsets", w.sector_onsets_s,
                 "Onset of each sector, seconds (36 increasing values, comma separated)")
      ->delimiter(',');
  cmd.add_option("--scale", w.environment_scale, "Range x scale -> BRIR distance");
  cmd.add_option("--fov-centre", w.filter.fov_centre_deg, "Field of view centre, degrees");
  cmd.add_option("--fov-width", w.filter.fov_width_deg, "Field of view width, degrees");
  cmd.add_option("--min-range", w.filter.min_range_m, "Play only ranges >= this, metres")
      ->check(CLI::Range(0.0, kMaxRange));
  cmd.add_option("--max-range", w.filter.max_range_m, "Play only ranges <= this, metres")
      ->check(CLI::Range(0.0, kMaxRange));
  cmd.add_option("--max-taps", w.filter.max_taps, "Ranging: only the N nearest taps (0: all)");
  cmd.add_option("--max-objects", w.max_objects, "Objects: the N nearest pseudo-objects");
  cmd.add_option("--object-jump", w.object_jump_m_per_deg,
                 "Objects: split where the range jumps more than this, metres per degree");
  cmd.add_option("--near-below", w.pitch.near_below_m, "Near taps: BRIR distance below, metres");
  cmd.add_option("--near-shift", w.pitch.near_semitones, "Near taps: pitch shift, semitones");
  cmd.add_option("--far-above", w.pitch.far_above_m, "Far taps: BRIR distance above, metres");
  cmd.add_option("--far-shift", w.pitch.far_semitones, "Far taps: pitch shift, semitones");
  cmd.add_flag("--invert-pitch", w.pitch.inverted, "Near higher, far lower (parking sensor)");
  cmd.add_flag("!--no-woosh", w.woosh_unknown, "Unknown sectors stay silent");
  cmd.add_option("--loudness", w.loudness.target_lufs,
                 "Integrated loudness target, LUFS (EBU R128); the -1 dBTP true-peak ceiling wins");
  cmd.add_option("--level", w.level,
                 "per-file: each WAV normalised to --loudness; fixed: one gain for every sweep, "
                 "set by the loudest sweep the BRIRs can play (levels compare across sweeps)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, audio::LevelMode>{{"per-file", audio::LevelMode::PerFile},
                                                  {"fixed", audio::LevelMode::Fixed}}))
      ->default_str("per-file");
}

void check_sweep_options(const SonifySetup& s) {
  const audio::PitchMapping& pitch = s.sweep.pitch;
  if (pitch.near_below_m > pitch.far_above_m)
    throw InputError("options --near-below " + number_text(pitch.near_below_m) + " and --far-above " +
                     number_text(pitch.far_above_m) + ": the near threshold must not exceed the far one");
  try {
    s.sweep.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("sweep options: ") + e.what());
  }
}

std::shared_ptr<const audio::BrirSet> load_brirs(const SonifySetup& s, bool quiet) {
  const double rate = s.sweep.sample_rate;
  if (!s.brir_dir.empty()) {
    audio::BrirSet set = read_brir_directory(s.brir_dir, rate);
    set.normalise_to_reference();
    return std::make_shared<const audio::BrirSet>(std::move(set));
  }
  const audio::BrirSynthConfig room = room_config(s.room, rate);
  if (!quiet) {
    const Eigen::Vector3d size = room.room.size();
    std::fprintf(stderr,
                 "sonomap: no --brir given: synthesising BRIRs in memory for a %.1fx%.1fx%.1f m "
                 "room, RT60 %.2f s, order %d, from %s\n",
                 size.x(), size.y(), size.z(), room.rt60, room.max_order,
                 s.room.hrir_file.string().c_str());
  }
  return std::make_shared<const audio::BrirSet>(synthesize_brirs(room, s.room.hrir_file, quiet, true));
}

namespace {
const char* const kEventsHeader =
    "time_s,sector,azimuth_deg,range_m,brir_distance_m,brir_azimuth_deg,pitch_semitones,sound,"
    "gain_db,loudness_lufs,true_peak_dbtp";
}  // namespace

std::string sweep_events_csv(const audio::SweepAudio& audio) {
  std::string out = std::string(kEventsHeader) + "\n";
  // The file's level, the same on every row: one gain for the whole sweep.
  char level[96];
  std::snprintf(level, sizeof level, "%.2f,%.2f,%.2f", audio.gain_db,
                audio.loudness.integrated_lufs, audio.loudness.true_peak_dbtp);
  char buf[320];
  for (const auto& e : audio.events) {
    char range[32] = "";
    if (std::isfinite(e.range_m)) std::snprintf(range, sizeof range, "%.4f", e.range_m);
    std::snprintf(buf, sizeof buf, "%.6f,%d,%.3f,%s,%.2f,%.1f,%.1f,%s,%s\n", e.time_s, e.sector,
                  e.azimuth_deg, range, e.brir_distance_m, e.brir_azimuth_deg, e.pitch_semitones,
                  audio::to_string(e.sound), level);
    out += buf;
  }
  return out;
}

fs::path events_path_for(const fs::path& wav) {
  fs::path p = wav;
  p.replace_extension(".events.csv");
  return p;
}

bool is_sonomap_sweep(const fs::path& file) {
  return first_line_is(file.extension() == ".csv" ? file : events_path_for(file), kEventsHeader);
}

void check_sweep_output(const fs::path& wav, const std::vector<fs::path>& inputs) {
  check_output_file(wav, is_sonomap_sweep, inputs);
  check_output_file(events_path_for(wav), is_sonomap_sweep, inputs);
}

void write_sweep(const audio::SweepAudio& audio, const fs::path& wav) {
  StagedFile wav_file(wav, is_sonomap_sweep);
  StagedFile events_file(events_path_for(wav), is_sonomap_sweep);
  write_wav(wav_file.path(), audio.sample_rate, audio.left, audio.right);
  events_file.write(sweep_events_csv(audio));
  events_file.commit();
  wav_file.commit();
}

}  // namespace sonomap::harness
