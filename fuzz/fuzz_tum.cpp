// SPDX-License-Identifier: GPL-3.0-or-later
// The recorded-sequence reader (`sonomap run SEQUENCE/`): one input holds depth.txt,
// groundtruth.txt and camera.yaml, separated by lines "=====". Then the first frame is
// loaded (its depth PNG, if depth.txt names depth/0.png, is a fixed valid image).
#include "fuzz_support.hpp"
#include "harness/formats/tum_io.hpp"
#include "harness/support/errors.hpp"

#include <array>
#include <string>

namespace {

std::array<std::string, 3> split(const std::string& text) {
  std::array<std::string, 3> parts;
  std::size_t begin = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t end = i < 2 ? text.find("\n=====\n", begin) : std::string::npos;
    parts[i] = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    if (end == std::string::npos) break;
    begin = end + 7;
  }
  return parts;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonomap;
  static const bool png_written = [] {
    std::filesystem::create_directories(fuzz::scratch() / "depth");
    harness::DepthImage16 image;
    image.width = 4;
    image.height = 3;
    image.pixels.assign(12, 5000);
    harness::write_png16(fuzz::scratch() / "depth" / "0.png", image);
    return true;
  }();
  (void)png_written;
  const auto parts = split(std::string(reinterpret_cast<const char*>(data), size));
  fuzz::write_file("depth.txt", parts[0]);
  fuzz::write_file("groundtruth.txt", parts[1]);
  fuzz::write_file("camera.yaml", parts[2]);
  try {
    const harness::TumSequence sequence = harness::read_tum_sequence(fuzz::scratch());
    if (!sequence.frames.empty()) harness::load_tum_frame(sequence, 0);
  } catch (const harness::InputError&) {
  }
  return 0;
}
