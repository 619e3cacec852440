// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/rosbag_wire.hpp"

#include "harness/support/errors.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <string>

namespace fs = std::filesystem;

namespace sonomap::harness {
namespace {


std::uint32_t little_endian_u32(const char* bytes) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[i]);
  return v;
}

// The fields of a record header ("name=value", each after its 4-byte length); nullopt when a
// field runs past the header's end.
std::optional<std::map<std::string, std::string>> header_fields(const std::string& header) {
  std::map<std::string, std::string> fields;
  for (size_t pos = 0; pos < header.size();) {
    if (header.size() - pos < 4) return std::nullopt;
    const std::uint32_t length = little_endian_u32(&header[pos]);
    if (length > header.size() - pos - 4) return std::nullopt;
    const std::string field = header.substr(pos + 4, length);
    const size_t eq = field.find('=');
    if (eq != std::string::npos) fields[field.substr(0, eq)] = field.substr(eq + 1);
    pos += 4 + length;
  }
  return fields;
}

// What is wrong with a record if it is a chunk claiming an uncompressed size it cannot have.
std::optional<std::string> chunk_problem(const std::map<std::string, std::string>& fields,
                                         std::uint64_t data_length) {
  const auto op = fields.find("op");
  if (op == fields.end() || op->second != std::string(1, '\x05')) return std::nullopt;  // not a chunk
  const auto compression = fields.find("compression"), unpacked = fields.find("size");
  const std::uint64_t claimed = unpacked != fields.end() && unpacked->second.size() == 4
                                    ? little_endian_u32(unpacked->second.data()) : ~std::uint64_t{0};
  const bool plain = compression != fields.end() && compression->second == "none";
  if (plain ? claimed == data_length : claimed <= kMaxBagMessageBytes) return std::nullopt;
  return "is a chunk claiming " + std::to_string(claimed) + " bytes uncompressed from " +
         std::to_string(data_length);
}

// rosbag reads a bag's first line with fgets into 1024 bytes (so the records start after at
// most 1023 characters, the newline included), its version from that line as
// "#ROS<type> V<major>.<minor>" with a type of under 100 characters, and takes
// major * 100 + minor = 200 as version 2.0. Returns where the records start when rosbag will
// read the file as version 2.0, nullopt when it will not (rosbag then reports it).
std::optional<std::uint64_t> version_200_records(std::ifstream& in) {
  constexpr size_t kLineBuffer = 1024, kTypeBuffer = 100;
  std::string line(kLineBuffer - 1, '\0');
  in.read(line.data(), static_cast<std::streamsize>(line.size()));
  line.resize(static_cast<size_t>(in.gcount()));
  in.clear();
  if (const size_t newline = line.find('\n'); newline != std::string::npos) line.resize(newline + 1);
  if (line.rfind("#ROS", 0) != 0) return std::nullopt;
  size_t type_end = 4;
  while (type_end < line.size() && !std::isspace(static_cast<unsigned char>(line[type_end]))) ++type_end;
  int major = 0, minor = 0;
  if (type_end - 4 >= kTypeBuffer ||
      std::sscanf(line.c_str() + type_end, " V%d.%d", &major, &minor) != 2 || major * 100 + minor != 200)
    return std::nullopt;
  return line.size();
}

}  // namespace

void check_bag_records(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::uint64_t size = fs::file_size(file);
  const std::optional<std::uint64_t> first_record = version_200_records(in);
  if (!first_record) return;
  auto fail = [&](std::uint64_t at, const std::string& what) {
    throw InputError(file.string(), 0, "",
                     "cannot read the ROS1 bag (truncated or corrupt: try 'rosbag reindex'): the record at byte " +
                         std::to_string(at) + " " + what + " (the file has " + std::to_string(size) + " bytes)");
  };
  char length[4];
  for (std::uint64_t at = *first_record; at < size;) {
    if (size - at < 4 || !in.seekg(static_cast<std::streamoff>(at)).read(length, 4)) fail(at, "is cut off");
    const std::uint64_t header_length = little_endian_u32(length);
    if (header_length > size - at - 4) fail(at, "claims a " + std::to_string(header_length) + "-byte header");
    std::string header(header_length, '\0');
    in.read(header.data(), static_cast<std::streamsize>(header_length));
    const std::uint64_t data_at = at + 4 + header_length;
    if (size - data_at < 4 || !in.read(length, 4)) fail(at, "is cut off after its header");
    const std::uint64_t data_length = little_endian_u32(length);
    if (data_length > size - data_at - 4) fail(at, "claims " + std::to_string(data_length) + " bytes of data");
    const auto fields = header_fields(header);
    if (!fields) fail(at, "has a malformed header (a field runs past its end)");
    if (const auto problem = chunk_problem(*fields, data_length)) fail(at, *problem);
    at = data_at + 4 + data_length;
  }
}

namespace {

// A serialised message read front to back: a length that runs past the end makes it invalid.
class Wire {
 public:
  Wire(const std::uint8_t* data, std::size_t size) : at_(data), left_(size) {}
  bool ok() const { return ok_; }
  void skip(std::size_t bytes) {
    if (bytes > left_) {
      ok_ = false;
      bytes = left_;
    }
    at_ += bytes;
    left_ -= bytes;
  }
  std::uint32_t u32() {
    const std::uint32_t v = left_ >= 4 ? little_endian_u32(reinterpret_cast<const char*>(at_)) : 0;
    skip(4);
    return v;
  }
  void string() { skip(u32()); }
  // An array's count, when `count` elements of at least `min_bytes` each fit in what is left
  // (ROS sizes the vector by the count before it reads the elements); else 0 and invalid.
  std::uint32_t array(std::size_t min_bytes) {
    const std::uint32_t count = u32();
    if (count <= left_ / min_bytes) return count;
    ok_ = false;
    return 0;
  }
  void header() {  // std_msgs/Header: seq, stamp, frame_id
    skip(12);
    string();
  }

 private:
  const std::uint8_t* at_;
  std::size_t left_;
  bool ok_ = true;
};

}  // namespace

bool bag_message_fits(BagMessageKind kind, const std::uint8_t* data, std::size_t size) {
  Wire w(data, size);
  w.header();
  switch (kind) {
    case BagMessageKind::Image:  // height, width, encoding, is_bigendian, step, data
      w.skip(8), w.string(), w.skip(5), w.skip(w.array(1));
      break;
    case BagMessageKind::PointCloud2: {  // height, width, fields, is_bigendian, steps, data, is_dense
      w.skip(8);
      const std::uint32_t fields = w.array(13);  // name (4 + n), offset, datatype, count
      for (std::uint32_t i = 0; i < fields && w.ok(); ++i) w.string(), w.skip(9);
      w.skip(9), w.skip(w.array(1)), w.skip(1);
      break;
    }
    case BagMessageKind::CameraInfo:  // height, width, distortion_model, D, K, R, P, binning, roi
      w.skip(8), w.string(), w.skip(8 * std::size_t{w.array(8)}), w.skip(8 * (9 + 9 + 12) + 8 + 17);
      break;
    case BagMessageKind::TransformStamped:  // child_frame_id, translation, rotation
      w.string(), w.skip(7 * 8);
      break;
    case BagMessageKind::PoseStamped:  // position, orientation
      w.skip(7 * 8);
      break;
  }
  return w.ok();
}

}  // namespace sonomap::harness
