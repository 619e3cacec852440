// SPDX-License-Identifier: GPL-3.0-or-later
// Checks of a ROS1 bag's bytes before rosbag and ROS's deserialiser read them. Both size their
// buffers from length fields before reading what the fields describe, so a corrupt bag asked
// for gigabytes (found by fuzz/fuzz_rosbag.cpp). No ROS header here: the checks walk the
// documented formats (bag format 2.0, ROS message serialisation) themselves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace sonomap::harness {

// The largest chunk (uncompressed) or message accepted: rosbag writes chunks of about 768 kB,
// and 1 GiB leaves room for any writer's choice and any single message.
constexpr std::uint32_t kMaxBagMessageBytes = std::uint32_t{1} << 30;

// Every top-level record of a version 2.0 bag (header length, header, data length, data) lies
// inside the file, every header's fields lie inside it, and a chunk claims no more than
// kMaxBagMessageBytes uncompressed (exactly its data length when it is not compressed).
// Throws InputError naming the file and the record's byte offset. Files of another version, or
// not bags at all, pass (rosbag reports them).
void check_bag_records(const std::filesystem::path& file);

// The message types sonomap reads from bags.
enum class BagMessageKind { Image, PointCloud2, CameraInfo, TransformStamped, PoseStamped };

// Whether every string and array length in a serialised message of `kind` fits in its `size`
// bytes (trailing bytes are allowed, as ROS's deserialiser allows them).
bool bag_message_fits(BagMessageKind kind, const std::uint8_t* data, std::size_t size);

}  // namespace sonomap::harness
