// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/resample.hpp"

#include <cmath>
#include <samplerate.h>
#include <stdexcept>
#include <string>

namespace sonomap::audio {

std::vector<float> resample(const std::vector<float>& input, double ratio) {
  if (!(ratio >= 1.0 / 256.0 && ratio <= 256.0))
    throw std::invalid_argument("resample: ratio " + std::to_string(ratio) +
                                " outside [1/256, 256]");
  if (input.empty()) return {};
  if (ratio == 1.0) return input;
  for (float x : input)
    if (!std::isfinite(x)) throw std::invalid_argument("resample: input is not finite");
  // Room for the whole output plus slack; libsamplerate flushes its filter at end of input.
  std::vector<float> output(static_cast<size_t>(std::ceil(input.size() * ratio)) + 16);
  SRC_DATA data{};
  data.data_in = input.data();
  data.input_frames = static_cast<long>(input.size());
  data.data_out = output.data();
  data.output_frames = static_cast<long>(output.size());
  data.src_ratio = ratio;
  data.end_of_input = 1;
  const int err = src_simple(&data, SRC_SINC_BEST_QUALITY, 1);
  if (err != 0) throw std::runtime_error(std::string("libsamplerate: ") + src_strerror(err));
  output.resize(static_cast<size_t>(data.output_frames_gen));
  return output;
}

std::vector<float> pitch_shift(const std::vector<float>& input, double semitones) {
  // Fewer samples played at the same rate raise every frequency by the inverse factor.
  return resample(input, std::pow(2.0, -semitones / 12.0));
}

}  // namespace sonomap::audio
