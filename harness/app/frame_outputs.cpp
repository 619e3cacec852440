// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/frame_outputs.hpp"

#include "audio/room_from_map.hpp"
#include "audio/sweep.hpp"
#include "harness/app/sonify.hpp"
#include "harness/report/pictures.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace fs = std::filesystem;

namespace sonomap::harness {

SweepMaker::SweepMaker(fs::path dir, fs::path brir_dir, double room_radius, bool quiet)
    : dir_(std::move(dir)), brir_dir_(std::move(brir_dir)), room_radius_(room_radius), quiet_(quiet) {}

SweepMaker::~SweepMaker() = default;

void SweepMaker::write(const FrameView& frame) {
  if (!renderer_) make_renderer(frame);
  const fs::path wav = dir_ / fmt::format("frame_{:06d}.wav", frame.index);
  const audio::SweepAudio audio = renderer_->render(*frame.circle);
  write_sweep(audio, wav);
  levels_.push_back({wav.filename().string(), audio.gain_db, audio.loudness.integrated_lufs,
                     audio.loudness.true_peak_dbtp, audio.peak_limited});
}

void SweepMaker::make_renderer(const FrameView& frame) {
  SonifySetup setup;
  std::shared_ptr<const audio::BrirSet> brirs;
  if (!brir_dir_.empty()) {
    setup.brir_dir = brir_dir_;
    brirs = load_brirs(setup, quiet_);
  } else {
    const RasterOrigin& o = frame.origin;
    std::vector<Eigen::Vector3f> surface;  // all heights: the room's floor and ceiling too
    frame.map->surface_points(o.position, room_radius_, surface);
    const audio::ShoeboxRoom box = audio::room_from_map(surface, o.position, o.ground_z);
    audio::BrirSynthConfig room =
        room_from_box(box.min_corner, box.max_corner, o.position, setup.room.rt60);
    room.listener_heading_deg = o.heading * 180.0 / M_PI;
    room.max_order = setup.room.order;
    brirs = std::make_shared<const audio::BrirSet>(synthesize_brirs(room, setup.room.hrir_file, true, true));
    const Eigen::Vector3d &lo = box.min_corner, &hi = box.max_corner;
    const nlohmann::json room_json{
        {"min_corner", {lo.x(), lo.y(), lo.z()}}, {"max_corner", {hi.x(), hi.y(), hi.z()}},
        {"listener", {o.position.x(), o.position.y(), o.position.z()}},
        {"listener_heading_deg", room.listener_heading_deg}, {"rt60", room.rt60},
        {"max_order", room.max_order}, {"hrir", setup.room.hrir_file.string()}};
    write_result_file(dir_ / "room.json", room_json.dump(2) + "\n");
  }
  renderer_ = std::make_unique<audio::SweepRenderer>(brirs, setup.sweep);
}

FrameOutputs::FrameOutputs(const fs::path& dir, const RunOptions& options,
                           const FrameSchedule& schedule, std::string scenario_name,
                           std::string mapper_name, const RasterConfig& raster)
    : pictures_(dir / "pictures"), schedule_(schedule), scenario_name_(std::move(scenario_name)),
      mapper_name_(std::move(mapper_name)), raster_(raster),
      sweeps_(dir / "sweeps", options.brir_dir, raster.max_range, options.quiet) {
  if (schedule.any_pictures()) fs::create_directory(pictures_);
  if (schedule.any_sweeps()) fs::create_directory(dir / "sweeps");
}

void FrameOutputs::write(const FrameView& frame) {
  if (schedule_.pictured(frame.index)) draw_pictures(frame);
  if (schedule_.swept(frame.index)) sweeps_.write(frame);
}

void FrameOutputs::draw_pictures(const FrameView& f) const {
  const eval::FrameEvaluation& e = *f.evaluation;
  const std::string stem = fmt::format("frame_{:06d}", f.index);
  plot_circle(pictures_ / (stem + "_circle.png"), *f.circle, e.has_truth ? &e.truth.circle : nullptr,
              f.origin, raster_,
              fmt::format("{}: {} circle, frame {} (t = {:.2f} s)", scenario_name_, mapper_name_,
                          f.index, f.time));
  plot_cylinder(pictures_ / (stem + "_cylinder.png"), *f.cylinder, raster_,
                fmt::format("{}: {} cylinder, frame {}", scenario_name_, mapper_name_, f.index));
  if (e.edf)
    plot_edf_arrows(pictures_ / (stem + "_edf.png"), *f.circle, *e.edf, f.origin, raster_,
                    fmt::format("{}: {} circle vs EDF, frame {} (slip median {:.1f} deg)",
                                scenario_name_, mapper_name_, f.index, e.slip.median_deg));
}

}  // namespace sonomap::harness
