// SPDX-License-Identifier: GPL-3.0-or-later
// The Python module's sweeps: a renderer made once (BRIRs loaded or synthesised, as `sonomap
// sonify` does with the same options and checks), then any number of circles rendered to a
// stereo buffer or written as a WAV and its event log under the output rules.
#pragma once

#include "audio/sweep.hpp"
#include "harness/app/sonify.hpp"

#include <filesystem>
#include <memory>
#include <mutex>

namespace sonomap::python {

class SweepSession {
 public:
  // Checks the sweep and room options (InputError naming the option) and loads or synthesises
  // the BRIR set.
  explicit SweepSession(harness::SonifySetup setup);
  double sample_rate() const { return renderer_->config().sample_rate; }
  // Leveled by the loudness rules: no sample above -1 dBFS.
  audio::SweepAudio render(const Circle& circle);
  // `wav` and its event log (sweep.events.csv), each staged and renamed; an existing file is
  // replaced only if it is a sweep sonomap wrote (InputError otherwise, nothing touched).
  audio::SweepAudio write(const Circle& circle, const std::filesystem::path& wav);

 private:
  harness::SonifySetup setup_;
  std::unique_ptr<audio::SweepRenderer> renderer_;
  std::mutex mutex_;
};

}  // namespace sonomap::python
