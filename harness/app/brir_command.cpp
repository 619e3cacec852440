// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap brir`: synthesise a BRIR set for a shoebox room on the paper's grid and write it as
// SOFA, one file per distance.
#include "harness/app/cli.hpp"
#include "harness/app/sonify.hpp"
#include "harness/formats/sofa_io.hpp"
#include "harness/support/output.hpp"

#include <cstdio>
#include <memory>

namespace sonomap::harness {

void add_brir_command(CLI::App& app, const GlobalOptions& global) {
  struct State {
    RoomOptions room;
    std::filesystem::path out;
    SofaMetadata meta;
  };
  auto state = std::make_shared<State>();
  CLI::App* cmd = app.add_subcommand(
      "brir", "Synthesise BRIRs of a shoebox room (image sources + late tail) on the paper's grid "
              "(azimuth every 3 deg, 0.4..4.0 m) and write one SOFA file per distance");
  add_room_options(*cmd, state->room);
  cmd->add_option("--out", state->out,
                  "Output directory: new, empty, or an earlier sonomap result (replaced atomically)")
      ->required();
  cmd->add_option("--author-contact", state->meta.author_contact,
                  "AES69 AuthorContact written in every file");
  cmd->add_option("--organization", state->meta.organization,
                  "AES69 Organization written in every file");
  cmd->callback([state, &global] {
    check_output_directory(state->out, {state->room.hrir_file});  // before the work
    const audio::BrirSynthConfig room = room_config(state->room, 48000.0);
    const audio::BrirSet set = synthesize_brirs(room, state->room.hrir_file, global.quiet, false);
    const Eigen::Vector3d lo = room.room.min_corner, hi = room.room.max_corner;
    const Eigen::Vector3d l = audio::listener_position(room);
    char comment[640];
    std::snprintf(comment, sizeof comment,
                  "shoebox room [%.2f,%.2f,%.2f]..[%.2f,%.2f,%.2f] m, listener (%.2f,%.2f,%.2f) "
                  "heading %.1f deg, RT60 %.3f s, image-source order %d, HRIRs %s, tail seed %llu; "
                  "normalised: the loudest response has unit energy",
                  lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), l.x(), l.y(), l.z(),
                  room.listener_heading_deg, room.rt60, room.max_order,
                  state->room.hrir_file.filename().string().c_str(), state->room.seed);
    SofaMetadata meta = state->meta;
    meta.comment = comment;
    meta.room_min = lo;
    meta.room_max = hi;
    meta.listener = l;
    meta.heading_deg = room.listener_heading_deg;
    write_brir_directory(state->out, set, meta);
    if (!global.quiet)
      std::fprintf(stderr, "wrote %zu SOFA files (%zu azimuths, %zu samples at %.0f Hz) to %s\n",
                   set.distance_count(), set.azimuth_count(), set.ir_length(), set.sample_rate(),
                   state->out.string().c_str());
  });
}

}  // namespace sonomap::harness
