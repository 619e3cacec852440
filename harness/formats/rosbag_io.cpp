// SPDX-License-Identifier: GPL-3.0-or-later
// The bag functions, in the library loaded on demand (harness/rosbag/rosbag_io.cpp).
#include "harness/formats/rosbag_io.hpp"

#include "harness/formats/modules.hpp"

namespace sonomap::harness {

std::unique_ptr<RecordReader> open_rosbag_reader(const SequenceSpec& spec) {
  return rosbag_functions().open_reader(spec);
}

std::vector<BagTopic> list_rosbag_topics(const std::filesystem::path& file) {
  return rosbag_functions().list_topics(file);
}

std::unique_ptr<RosbagWriter> open_rosbag_writer(const std::filesystem::path& file, BagCompression compression) {
  return rosbag_functions().open_writer(file, compression);
}

}  // namespace sonomap::harness
