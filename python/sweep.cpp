// SPDX-License-Identifier: GPL-3.0-or-later
#include "python/sweep.hpp"

#include "harness/support/errors.hpp"

#include <stdexcept>

namespace sonomap::python {

SweepSession::SweepSession(harness::SonifySetup setup) : setup_(std::move(setup)) {
  harness::check_sweep_options(setup_);
  renderer_ = std::make_unique<audio::SweepRenderer>(harness::load_brirs(setup_, true), setup_.sweep);
}

audio::SweepAudio SweepSession::render(const Circle& circle) {
  std::lock_guard<std::mutex> lock(mutex_);
  return renderer_->render(circle);
}

audio::SweepAudio SweepSession::write(const Circle& circle, const std::filesystem::path& wav) {
  const std::filesystem::path& brirs = setup_.brir_dir;
  harness::check_sweep_output(wav, {brirs.empty() ? setup_.room.hrir_file : brirs});
  audio::SweepAudio audio = render(circle);
  harness::write_sweep(audio, wav);
  return audio;
}

}  // namespace sonomap::python
