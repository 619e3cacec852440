// SPDX-License-Identifier: GPL-3.0-or-later
// Checks of a ROS1 bag's bytes before rosbag and ROS's deserialiser read them. Both size their
// buffers from length fields before reading what the fields describe, so a corrupt bag asked
// for gigabytes (found by fuzz/fuzz_rosbag.cpp). No ROS header here: the checks walk the
// documented formats (bag format 2.0, ROS message serialisation) themselves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace sonomap::harness {

// The largest chunk (uncompressed) or message accepted: rosbag writes chunks of about 768 kB,
// and 1 GiB leaves room for any writer's choice and any single message.
constexpr std::uint32_t kMaxBagMessageBytes = std::uint32_t{1} << 30;

// Uncompresses a chunk's data (compression "lz4" or "bz2") into `out`, sized beforehand to
// the chunk's claimed uncompressed size; false when the data do not uncompress to that size.
using ChunkInflater = std::function<bool(const std::string& compression, const std::string& packed,
                                         std::string& out)>;

// What rosbag reads of a version 2.0 bag lies inside what holds it: every top-level record
// (header length, header, data length, data) inside the file and every header's fields inside
// the header (a connection's data are a header too: its topic's); a chunk claims no more than kMaxBagMessageBytes uncompressed (exactly its data
// length when it is not compressed), and its records lie inside it; the file header's index
// position and every chunk info's chunk position are a record's start; an index record's
// entries fit in its data, and each points, in the chunk before it, at a record from which
// rosbag reaches a message (skipping connection records) inside the chunk. Compressed chunks
// are opened with `inflate` (without one, their insides are not checked). Throws InputError
// naming the file and the record's byte offset (and the chunk's), or the version line for a
// bag of another format than 2.0. Files that are not bags at all pass (rosbag reports them).
void check_bag_records(const std::filesystem::path& file, const ChunkInflater& inflate = {});

// The message types sonomap reads from bags.
enum class BagMessageKind { Image, PointCloud2, CameraInfo, TransformStamped, PoseStamped };

// Whether every string and array length in a serialised message of `kind` fits in its `size`
// bytes (trailing bytes are allowed, as ROS's deserialiser allows them).
bool bag_message_fits(BagMessageKind kind, const std::uint8_t* data, std::size_t size);

}  // namespace sonomap::harness
