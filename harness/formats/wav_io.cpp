// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/wav_io.hpp"

#include "harness/support/errors.hpp"

#include <cmath>
#include <sndfile.h>
#include <stdexcept>
#include <string>

namespace sonomap::harness {

void write_wav(const std::filesystem::path& path, double sample_rate, const std::vector<float>& left,
               const std::vector<float>& right) {
  if (left.size() != right.size()) throw std::invalid_argument("write_wav: channel lengths differ");
  if (!(sample_rate >= 1.0 && sample_rate <= 1e6)) throw std::invalid_argument("write_wav: rate");
  SF_INFO info{};
  info.samplerate = static_cast<int>(std::lround(sample_rate));
  info.channels = 2;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  // The last line of defence of the loudness rules (audio/loudness.hpp): nothing above the
  // ceiling is ever written, whatever computed it.
  for (const auto* channel : {&left, &right})
    for (float x : *channel)
      if (!(std::abs(x) <= kWavCeiling))
        throw std::logic_error(path.string() + ": refusing to write a sample of " +
                               std::to_string(x) + " (above -1 dBFS, or not finite)");
  SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
  if (!f) throw std::runtime_error(path.string() + ": cannot write WAV: " + sf_strerror(nullptr));
  // libsndfile's PEAK chunk carries a timestamp: without it two renders are byte-identical.
  sf_command(f, SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
  std::vector<float> frames(left.size() * 2);
  for (size_t i = 0; i < left.size(); ++i) {
    frames[2 * i] = left[i];
    frames[2 * i + 1] = right[i];
  }
  const sf_count_t written = sf_writef_float(f, frames.data(), static_cast<sf_count_t>(left.size()));
  const std::string err = sf_strerror(f);
  sf_close(f);
  if (written != static_cast<sf_count_t>(left.size()))
    throw std::runtime_error(path.string() + ": short WAV write: " + err);
}

StereoAudio read_wav(const std::filesystem::path& path) {
  SF_INFO info{};
  SNDFILE* f = sf_open(path.c_str(), SFM_READ, &info);
  if (!f) throw InputError(path.string(), 0, "", std::string("cannot read WAV: ") + sf_strerror(nullptr));
  if (info.channels < 1 || info.channels > 2 || info.frames < 0) {
    sf_close(f);
    throw InputError(path.string(), 0, "", "need a mono or stereo WAV");
  }
  std::vector<float> frames(static_cast<size_t>(info.frames) * info.channels);
  const sf_count_t got = sf_readf_float(f, frames.data(), info.frames);
  sf_close(f);
  StereoAudio out;
  out.sample_rate = info.samplerate;
  out.left.resize(static_cast<size_t>(got));
  out.right.resize(static_cast<size_t>(got));
  for (sf_count_t i = 0; i < got; ++i) {
    out.left[i] = frames[i * info.channels];
    out.right[i] = frames[i * info.channels + info.channels - 1];
  }
  return out;
}

}  // namespace sonomap::harness
