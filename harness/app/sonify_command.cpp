// SPDX-License-Identifier: GPL-3.0-or-later
// `sonomap sonify CIRCLE.csv --out sweep.wav`: one binaural sweep of a circle (circle_io.hpp
// documents the CSV), written with its event log sweep.events.csv.
#include "harness/app/cli.hpp"
#include "harness/app/sonify.hpp"
#include "harness/formats/circle_io.hpp"

#include <cstdio>
#include <memory>

namespace sonomap::harness {

void add_sonify_command(CLI::App& app, const GlobalOptions& global) {
  struct State {
    std::filesystem::path circle;
    std::filesystem::path out;
    SonifySetup setup;
  };
  auto state = std::make_shared<State>();
  CLI::App* cmd = app.add_subcommand(
      "sonify", "Render one binaural sweep of a circle CSV (header 'bin,range', 360 rows, empty "
                "range = unknown) to a stereo WAV and an event CSV");
  cmd->add_option("circle", state->circle, "Circle CSV")->required();
  cmd->add_option("--out", state->out,
                  "Output WAV (events go to <name>.events.csv); replaces only a sweep sonomap wrote")
      ->required();
  add_sonify_options(*cmd, state->setup);
  cmd->callback([state, &global] {
    const std::filesystem::path& brirs = state->setup.brir_dir;
    check_sweep_output(state->out, {state->circle, brirs.empty() ? state->setup.room.hrir_file : brirs});
    const Circle circle = read_circle_csv(state->circle);
    check_sweep_options(state->setup);
    audio::SweepRenderer renderer(load_brirs(state->setup, global.quiet), state->setup.sweep);
    const audio::SweepAudio audio = renderer.render(circle);
    write_sweep(audio, state->out);
    if (!global.quiet) {
      size_t taps = 0;
      for (const auto& e : audio.events) taps += e.sound == audio::SoundKind::Tap;
      std::fprintf(stderr, "wrote %s (%.2f s, %zu taps, %zu wooshes) and %s\n",
                   state->out.string().c_str(), audio.left.size() / audio.sample_rate, taps,
                   audio.events.size() - taps, events_path_for(state->out).string().c_str());
    }
  });
}

}  // namespace sonomap::harness
