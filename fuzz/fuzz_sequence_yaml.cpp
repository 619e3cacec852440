// SPDX-License-Identifier: GPL-3.0-or-later
// The sequence-file reader (`sonomap run SEQUENCE.yaml`: a recording's source, camera, poses,
// world and truth) on arbitrary bytes, then the frame names its depth and pose patterns give.
#include "fuzz_support.hpp"
#include "harness/formats/sequence_yaml.hpp"
#include "harness/support/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonomap;
  const auto file = fuzz::write_file("sequence.yaml", std::string(reinterpret_cast<const char*>(data), size));
  try {
    if (!harness::is_sequence_file(file)) return 0;
    const harness::SequenceSpec spec = harness::load_sequence_spec(file);
    for (const long long i : {0LL, 1LL, 999999LL})
      for (const std::string& pattern : {spec.depth_pattern, spec.pose_pattern})
        if (!pattern.empty()) harness::expand_frame_pattern(pattern, spec.first + i);
  } catch (const harness::InputError&) {
  }
  return 0;
}
