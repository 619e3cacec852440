// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/tum_io.hpp"

#include "harness/support/errors.hpp"
#include "harness/support/fields.hpp"
#include "harness/support/output.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <system_error>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

// --- libpng, which reports errors by longjmp: the functions that call setjmp hold only plain
// data, so no destructor is ever skipped.

struct PngError {
  char message[256] = "unknown libpng error";
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

bool write_png16_raw(std::FILE* file, int width, int height, const std::uint16_t* pixels,
                     PngError* error) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, error, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_compression_level(png, 1);  // depth images compress well even at the fastest level
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 16,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (host_is_little_endian()) png_set_swap(png);  // PNG stores 16-bit samples big-endian
  for (int y = 0; y < height; ++y)
    png_write_row(png, reinterpret_cast<png_const_bytep>(pixels + static_cast<std::size_t>(y) * width));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

// On success *pixels is malloc'ed (width * height samples); the caller frees it.
bool read_png16_raw(std::FILE* file, int* width, int* height, std::uint16_t** pixels,
                    png_bytep** rows, PngError* error) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, error, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::free(*pixels);
    std::free(*rows);
    *pixels = nullptr;
    *rows = nullptr;
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info);
  const png_uint_32 h = png_get_image_height(png, info);
  if (png_get_bit_depth(png, info) != 16 || png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY)
    png_error(png, "expected a 16-bit greyscale PNG (a depth image)");
  if (static_cast<unsigned long long>(w) * h > (1ull << 28)) png_error(png, "image too large");
  if (host_is_little_endian()) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  *pixels = static_cast<std::uint16_t*>(std::malloc(sizeof(std::uint16_t) * w * h));
  *rows = static_cast<png_bytep*>(std::malloc(sizeof(png_bytep) * h));
  if (!*pixels || !*rows) png_error(png, "out of memory");
  for (png_uint_32 y = 0; y < h; ++y)
    (*rows)[y] = reinterpret_cast<png_bytep>(*pixels + static_cast<std::size_t>(y) * w);
  png_read_image(png, *rows);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  std::free(*rows);
  *rows = nullptr;
  *width = static_cast<int>(w);
  *height = static_cast<int>(h);
  return true;
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// --- text files ----------------------------------------------------------------------------

std::string fixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

std::string pose_line(double timestamp, const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Quaterniond q(pose.linear());
  std::string line = fixed(timestamp, 6);
  for (double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) line += " " + fixed(v, 9);
  return line + "\n";
}

// Timestamps strictly increase down a file: an unsorted or repeated one is named by its line.
void check_time_order(const fs::path& file, int line, double time, double& previous) {
  if (!(time > previous))
    throw InputError(file.string(), line, "",
                     "timestamp " + number_text(time) + " is not after the previous one (" +
                         number_text(previous) + "); timestamps must strictly increase");
  previous = time;
}

// Calls `row(line_number, fields)` for each line that is neither empty nor a # comment.
template <typename Row>
void for_each_row(const fs::path& file, Row row) {
  std::ifstream in(file);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec) || !in)
    throw InputError(file.string(), 0, "", "missing or unreadable (expected a TUM RGB-D sequence)");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string w; fields >> w;) words.push_back(w);
    if (words.empty() || words[0][0] == '#') continue;
    row(number, words);
  }
}

struct StampedPose {
  double time;
  Eigen::Isometry3d pose;
};

std::vector<StampedPose> read_groundtruth(const fs::path& file) {
  std::vector<StampedPose> poses;
  double previous = -INFINITY;
  for_each_row(file, [&](int line, const std::vector<std::string>& words) {
    static const char* const kFields[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
    if (words.size() != 8)
      throw InputError(file.string(), line, "",
                       "expected 8 numbers: timestamp tx ty tz qx qy qz qw; found " + std::to_string(words.size()) +
                           " fields");
    double v[8];
    for (std::size_t i = 0; i < 8; ++i)
      if (!parse_number(words[i], v[i]))
        throw InputError(file.string(), line, kFields[i], "'" + words[i] + "' is not a finite number");
    check_time_order(file, line, v[0], previous);
    if (std::max({std::abs(v[1]), std::abs(v[2]), std::abs(v[3])}) > kMaxPosition)
      throw InputError(file.string(), line, "",
                       "position beyond " + number_text(kMaxPosition) + " m of the origin");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw InputError(file.string(), line, "", "the quaternion qx qy qz qw is not unit length");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = q.normalized().toRotationMatrix();
    pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    poses.push_back({v[0], pose});
  });
  return poses;
}

// The pose nearest in time, or nullptr if none is within max_difference.
const StampedPose* nearest(const std::vector<StampedPose>& poses, double t, double max_difference) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const StampedPose& p, double time) { return p.time < time; });
  const StampedPose* best = nullptr;
  if (after != poses.end()) best = &*after;
  if (after != poses.begin()) {
    const StampedPose* before = &*(after - 1);
    if (!best || t - before->time <= best->time - t) best = before;
  }
  return best && std::abs(best->time - t) <= max_difference ? best : nullptr;
}

}  // namespace

void write_png16(const fs::path& file, const DepthImage16& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height)
    throw std::invalid_argument("write_png16: pixel count does not match width x height");
  FilePtr out(std::fopen(file.c_str(), "wb"));
  if (!out) throw std::runtime_error("cannot create " + file.string());
  PngError error;
  if (!write_png16_raw(out.get(), image.width, image.height, image.pixels.data(), &error))
    throw std::runtime_error("cannot write " + file.string() + ": " + error.message);
  if (std::fclose(out.release()) != 0) throw std::runtime_error("cannot write " + file.string());
}

DepthImage16 read_png16(const fs::path& file) {
  FilePtr in(std::fopen(file.c_str(), "rb"));
  std::error_code ec;
  if (!in || !fs::is_regular_file(file, ec))
    throw InputError(file.string(), 0, "", "missing or unreadable depth image");
  PngError error;
  int width = 0, height = 0;
  std::uint16_t* pixels = nullptr;
  png_bytep* rows = nullptr;
  if (!read_png16_raw(in.get(), &width, &height, &pixels, &rows, &error))
    throw InputError(file.string(), 0, "", std::string("cannot read the PNG: ") + error.message);
  DepthImage16 image;
  image.width = width;
  image.height = height;
  image.pixels.assign(pixels, pixels + static_cast<std::size_t>(width) * height);
  std::free(pixels);
  return image;
}

TumWriter::TumWriter(fs::path dir, CameraFile camera)
    : dir_(std::move(dir)), camera_(std::move(camera)) {
  fs::create_directories(dir_ / "depth");
  const std::string origin = "# file: 'sonomap render " + camera_.name + "'\n";
  depth_list_ = "# depth maps\n" + origin + "# timestamp filename\n";
  groundtruth_ = "# ground truth trajectory\n" + origin + "# timestamp tx ty tz qx qy qz qw\n";
}

void TumWriter::add(const Frame& frame, const Eigen::Isometry3d& world_T_camera_true) {
  DepthImage16 image;
  image.width = frame.width;
  image.height = frame.height;
  image.pixels.resize(frame.depth.size());
  for (std::size_t i = 0; i < frame.depth.size(); ++i) {
    const double units = std::round(static_cast<double>(frame.depth[i]) * camera_.depth_scale);
    image.pixels[i] = units >= 1.0 && units <= 65535.0 ? static_cast<std::uint16_t>(units) : 0;
  }
  const std::string stamp = fixed(frame.time, 6);
  const std::string name = "depth/" + stamp + ".png";
  write_png16(dir_ / name, image);
  depth_list_ += stamp + " " + name + "\n";
  groundtruth_ += pose_line(frame.time, world_T_camera_true);
}

void TumWriter::finish() {
  write_text_file(dir_ / "depth.txt", depth_list_);
  write_text_file(dir_ / "groundtruth.txt", groundtruth_);
  write_text_file(dir_ / "camera.yaml", camera_file_text(camera_));
}

TumSequence read_tum_sequence(const fs::path& dir, double max_time_difference) {
  TumSequence sequence;
  sequence.dir = dir;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(dir.string(), 0, "", "not a directory (expected a TUM RGB-D sequence)");
  sequence.camera = load_camera_file(dir / "camera.yaml");
  const std::vector<StampedPose> poses = read_groundtruth(dir / "groundtruth.txt");
  const fs::path depth_list = dir / "depth.txt";
  double previous = -INFINITY;
  for_each_row(depth_list, [&](int line, const std::vector<std::string>& words) {
    TumFrameInfo info;
    if (words.size() != 2)
      throw InputError(depth_list.string(), line, "",
                       "expected: timestamp filename; found " + std::to_string(words.size()) + " fields");
    if (!parse_number(words[0], info.timestamp))
      throw InputError(depth_list.string(), line, "timestamp", "'" + words[0] + "' is not a finite number");
    check_time_order(depth_list, line, info.timestamp, previous);
    info.depth_file = dir / words[1];
    const StampedPose* pose = nearest(poses, info.timestamp, max_time_difference);
    if (!pose) {
      ++sequence.frames_without_pose;
      return;
    }
    info.world_T_camera = pose->pose;
    sequence.frames.push_back(std::move(info));
  });
  if (sequence.frames.empty())
    throw InputError(depth_list.string(), 0, "",
                     "no depth frame has a ground-truth pose within " +
                         std::to_string(max_time_difference) + " s");
  return sequence;
}

DepthRecord read_tum_record(const TumSequence& sequence, std::size_t i) {
  if (i >= sequence.frames.size())
    throw std::out_of_range("read_tum_record: frame " + std::to_string(i) + " of " +
                            std::to_string(sequence.frames.size()));
  const TumFrameInfo& info = sequence.frames[i];
  const sim::CameraSpec& camera = sequence.camera.camera;
  const DepthImage16 image = read_png16(info.depth_file);
  if (image.width != camera.width || image.height != camera.height)
    throw InputError(info.depth_file.string(), 0, "",
                     "the image is " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " but camera.yaml says " +
                         std::to_string(camera.width) + "x" + std::to_string(camera.height));
  DepthRecord record;
  record.time = info.timestamp;
  record.width = image.width;
  record.height = image.height;
  record.depth = depth_from_units(image.pixels, sequence.camera.depth_scale);
  record.world_T_camera = info.world_T_camera;
  return record;
}

Frame load_tum_frame(const TumSequence& sequence, std::size_t i) {
  return frame_from_record(static_cast<int>(i), read_tum_record(sequence, i),
                           sequence.frames.front().timestamp, sequence.camera.camera);
}

}  // namespace sonomap::harness
