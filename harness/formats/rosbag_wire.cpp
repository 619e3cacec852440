// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/rosbag_wire.hpp"

#include "harness/support/errors.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <vector>
#include <algorithm>
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

// rosbag reads a bag's first line with fgets into 1024 bytes and counts it to its first NUL,
// so the records start after at most 1023 characters, after the newline or at a NUL. It reads
// the version from that line with sscanf's "#ROS%s V%d.%d", the type into 100 bytes (%s
// skips white space, then takes a word of any length), and takes major * 100 + minor = 200
// as version 2.0. Returns where the records start when rosbag will read the file as version
// 2.0, nullopt when it is no bag (rosbag then reports it). Throws InputError when the type is
// too long for rosbag's buffer, or the bag is of another format.
std::optional<std::uint64_t> version_200_records(std::ifstream& in, const fs::path& file) {
  constexpr size_t kLineBuffer = 1024, kTypeBuffer = 100;
  std::string line(kLineBuffer - 1, '\0');
  in.read(line.data(), static_cast<std::streamsize>(line.size()));
  line.resize(static_cast<size_t>(in.gcount()));
  in.clear();
  if (const size_t newline = line.find('\n'); newline != std::string::npos) line.resize(newline + 1);
  line.resize(std::min(line.size(), line.find('\0')));
  if (line.rfind("#ROS", 0) != 0) return std::nullopt;
  const auto space = [&](size_t i) { return std::isspace(static_cast<unsigned char>(line[i])) != 0; };
  size_t type_begin = 4;
  while (type_begin < line.size() && space(type_begin)) ++type_begin;
  size_t type_end = type_begin;
  while (type_end < line.size() && !space(type_end)) ++type_end;
  if (type_end - type_begin >= kTypeBuffer)
    throw InputError(file.string(), 1, "",
                     "not a ROS1 bag rosbag can read: the version line's log type is " +
                         std::to_string(type_end - type_begin) + " characters long (rosbag reads at most " +
                         std::to_string(kTypeBuffer - 1) + ")");
  int major = 0, minor = 0;
  if (type_end == type_begin || std::sscanf(line.c_str() + type_end, " V%d.%d", &major, &minor) != 2)
    return std::nullopt;
  // rosbag also reads the format of 2009 (1.2), by code these checks do not cover.
  if (major * 100 + minor != 200)
    throw InputError(file.string(), 1, "",
                     "bag format " + std::to_string(major) + "." + std::to_string(minor) +
                         " is not read here: only format 2.0 (rosbag's since 2010)");
  return line.size();
}

// Where records are read from: the file, or a chunk's (uncompressed) data.
class FileBytes {
 public:
  explicit FileBytes(std::ifstream& in, std::uint64_t size) : in_(in), size_(size) {}
  std::uint64_t size() const { return size_; }
  bool read(std::uint64_t at, std::uint64_t n, char* out) {
    return static_cast<bool>(in_.seekg(static_cast<std::streamoff>(at)).read(out, static_cast<std::streamsize>(n)));
  }

 private:
  std::ifstream& in_;
  std::uint64_t size_;
};

class MemoryBytes {
 public:
  explicit MemoryBytes(const std::string& bytes) : bytes_(bytes) {}
  std::uint64_t size() const { return bytes_.size(); }
  bool read(std::uint64_t at, std::uint64_t n, char* out) {
    if (at > bytes_.size() || n > bytes_.size() - at) return false;
    std::copy_n(bytes_.data() + at, n, out);
    return true;
  }

 private:
  const std::string& bytes_;
};

// One record: header length, header ("name=value" fields), data length, data.
struct Record {
  std::uint64_t at = 0, data_at = 0, data_length = 0;
  std::map<std::string, std::string> fields;
  std::uint64_t end() const { return data_at + data_length; }
  bool is(char op) const {
    const auto f = fields.find("op");
    return f != fields.end() && f->second == std::string(1, op);
  }
  // A little-endian field of 4 or 8 bytes; nullopt when absent or of another size.
  std::optional<std::uint64_t> number(const std::string& name) const {
    const auto f = fields.find(name);
    if (f == fields.end() || (f->second.size() != 4 && f->second.size() != 8)) return std::nullopt;
    std::uint64_t v = little_endian_u32(f->second.data());
    if (f->second.size() == 8) v |= std::uint64_t{little_endian_u32(f->second.data() + 4)} << 32;
    return v;
  }
};

constexpr char kOpMessage = '\x02', kOpFileHeader = '\x03', kOpIndex = '\x04', kOpChunk = '\x05',
               kOpChunkInfo = '\x06', kOpConnection = '\x07';

// Reads the record at `at` (not its data); what is wrong with it, if anything.
template <class Bytes>
std::optional<std::string> read_record(Bytes& bytes, std::uint64_t at, Record& out) {
  const std::uint64_t size = bytes.size();
  char length[4];
  if (size - at < 4 || !bytes.read(at, 4, length)) return "is cut off";
  const std::uint64_t header_length = little_endian_u32(length);
  if (header_length > size - at - 4) return "claims a " + std::to_string(header_length) + "-byte header";
  std::string header(header_length, '\0');
  const std::uint64_t data_at = at + 4 + header_length;
  if (!bytes.read(at + 4, header_length, header.data()) || size - data_at < 4 || !bytes.read(data_at, 4, length))
    return "is cut off after its header";
  out.at = at;
  out.data_at = data_at + 4;
  out.data_length = little_endian_u32(length);
  if (out.data_length > size - out.data_at) return "claims " + std::to_string(out.data_length) + " bytes of data";
  auto fields = header_fields(header);
  if (!fields) return "has a malformed header (a field runs past its end)";
  out.fields = std::move(*fields);
  return std::nullopt;
}

// A connection record's data are a header of their own (topic, type, definition), which
// rosbag parses as it parses record headers.
constexpr const char* kBadConnection = "is a connection whose data (its topic's header) have a field running past their end";

// The offsets in a chunk's uncompressed data from which rosbag reaches a message: a message
// record's start, or a connection record's whose next record (inside the chunk) reaches one.
// Every record of the chunk must lie inside it, and every connection's data be a header.
std::set<std::uint64_t> message_starts(const std::string& chunk, const std::function<void(const std::string&)>& fail) {
  MemoryBytes bytes(chunk);
  std::vector<std::pair<std::uint64_t, char>> records;  // start, op
  for (std::uint64_t at = 0; at < chunk.size();) {
    Record r;
    if (const auto problem = read_record(bytes, at, r))
      fail("holds, at byte " + std::to_string(at) + " of its data, a record that " + *problem);
    if (r.is(kOpConnection) && !header_fields(chunk.substr(r.data_at, r.data_length)))
      fail("holds, at byte " + std::to_string(at) + " of its data, a record that " + kBadConnection);
    records.emplace_back(at, r.is(kOpMessage) ? kOpMessage : r.is(kOpConnection) ? kOpConnection : '\0');
    at = r.end();
  }
  std::set<std::uint64_t> starts;
  bool next_reaches = false;
  for (auto r = records.rbegin(); r != records.rend(); ++r) {
    next_reaches = r->second == kOpMessage || (r->second == kOpConnection && next_reaches);
    if (next_reaches) starts.insert(r->first);
  }
  return starts;
}

// Index entries (ver 1: sec, nsec, offset; 12 bytes each) must fit in the data, and each
// offset be in `starts` (the message starts of the chunk before the index; null: not known).
std::optional<std::string> index_problem(const Record& index, const std::string& data,
                                         const std::set<std::uint64_t>* starts) {
  if (index.number("ver") != std::uint64_t{1}) return std::nullopt;  // rosbag refuses it
  const std::uint64_t count = index.number("count").value_or(0);
  if (count > data.size() / 12) return "is an index claiming " + std::to_string(count) + " entries";
  if (!starts) return std::nullopt;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint64_t offset = little_endian_u32(&data[12 * i + 8]);
    if (!starts->count(offset))
      return "is an index whose entry " + std::to_string(i) + " points at byte " + std::to_string(offset) +
             " of its chunk, where no message starts";
  }
  return std::nullopt;
}

// A chunk's uncompressed data (`data` as read); nullopt when it cannot be had here (another
// compression, or no inflater).
std::optional<std::string> chunk_contents(const Record& chunk, std::string data, const ChunkInflater& inflate,
                                          const std::function<void(const std::string&)>& fail) {
  const auto field = chunk.fields.find("compression");
  if (field == chunk.fields.end()) return std::nullopt;  // rosbag refuses the chunk
  const std::string& compression = field->second;
  if (compression == "none") return data;
  if (!inflate || (compression != "lz4" && compression != "bz2")) return std::nullopt;
  std::string unpacked(*chunk.number("size"), '\0');
  if (!inflate(compression, data, unpacked))
    fail("is a chunk whose data do not uncompress (" + compression + ") to the " + std::to_string(unpacked.size()) +
         " bytes it claims");
  return unpacked;
}

}  // namespace

void check_bag_records(const fs::path& file, const ChunkInflater& inflate) {
  std::ifstream in(file, std::ios::binary);
  FileBytes bytes(in, fs::file_size(file));
  const std::optional<std::uint64_t> first_record = version_200_records(in, file);
  if (!first_record) return;
  auto fail = [&](std::uint64_t at, const std::string& what) {
    throw InputError(file.string(), 0, "",
                     "cannot read the ROS1 bag (truncated or corrupt: try 'rosbag reindex'): the record at byte " +
                         std::to_string(at) + " " + what + " (the file has " + std::to_string(bytes.size()) + " bytes)");
  };
  std::set<std::uint64_t> record_starts, chunk_starts;
  std::optional<std::set<std::uint64_t>> last_chunk;  // its message starts, if checked
  std::vector<std::pair<std::uint64_t, std::uint64_t>> index_positions, chunk_positions;  // (record, position)
  std::string data;
  for (std::uint64_t at = *first_record; at < bytes.size();) {
    Record r;
    if (const auto problem = read_record(bytes, at, r)) fail(at, *problem);
    record_starts.insert(at);
    const auto fail_here = [&](const std::string& what) { fail(at, what); };
    if (r.is(kOpChunk) || r.is(kOpIndex) || r.is(kOpConnection)) {
      data.resize(r.data_length);
      if (!bytes.read(r.data_at, r.data_length, data.data())) fail(at, "is cut off in its data");
    }
    if (r.is(kOpChunk)) {
      if (const auto problem = chunk_problem(r.fields, r.data_length)) fail(at, *problem);
      chunk_starts.insert(at);
      const std::optional<std::string> contents = chunk_contents(r, std::move(data), inflate, fail_here);
      last_chunk.reset();
      if (contents) last_chunk = message_starts(*contents, [&](const std::string& what) { fail(at, "is a chunk that " + what); });
    } else if (r.is(kOpConnection)) {
      if (!header_fields(data)) fail(at, kBadConnection);
    } else if (r.is(kOpIndex)) {
      if (const auto problem = index_problem(r, data, last_chunk ? &*last_chunk : nullptr)) fail(at, *problem);
    } else if (r.is(kOpFileHeader)) {
      index_positions.emplace_back(at, r.number("index_pos").value_or(~std::uint64_t{0}));
    } else if (r.is(kOpChunkInfo)) {
      chunk_positions.emplace_back(at, r.number("chunk_pos").value_or(~std::uint64_t{0}));
    }
    at = r.end();
  }
  // rosbag finds the connections and chunk infos at the index position, and the chunks (and
  // the index records after each) at the chunk infos' positions.
  for (const auto& [at, index_at] : index_positions)
    if (index_at != bytes.size() && !record_starts.count(index_at))
      fail(at, "places the index at byte " + std::to_string(index_at) + ", where no record starts");
  for (const auto& [at, chunk_at] : chunk_positions)
    if (!chunk_starts.count(chunk_at))
      fail(at, "names a chunk at byte " + std::to_string(chunk_at) + ", where none starts");
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
