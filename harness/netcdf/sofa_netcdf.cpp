// SPDX-License-Identifier: GPL-3.0-or-later
// libsonomap_netcdf_io.so: SOFA containers through the netCDF-4 C API, loaded on demand
// (harness/formats/modules.hpp). Writing follows AES69's convention for room responses,
// SingleRoomMIMOSRIR 1.0, in the layout libmysofa 1.3.1 loads (harness/formats/sofa_io.hpp).
#include "harness/formats/modules.hpp"

#include <Eigen/Geometry>
#include <netcdf.h>

#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

constexpr double kPi = 3.14159265358979323846;

int open_status(const fs::path& file) {
  int ncid = 0;
  const int status = nc_open(file.c_str(), NC_NOWRITE, &ncid);
  if (status == NC_NOERR) nc_close(ncid);
  return status;
}

std::string status_text(int status) { return nc_strerror(status); }


class NetcdfFile {
 public:
  explicit NetcdfFile(const fs::path& path) : path_(path) {
    check(nc_create(path.c_str(), NC_NETCDF4 | NC_CLOBBER, &id_), "create");
  }
  ~NetcdfFile() {
    if (id_ >= 0) nc_close(id_);
  }
  void check(int status, const std::string& what) const {
    if (status != NC_NOERR)
      throw std::runtime_error(path_.string() + ": netCDF " + what + ": " + nc_strerror(status));
  }
  int id() const { return id_; }
  int dim(const char* name, size_t length) {
    int d = -1;
    check(nc_def_dim(id_, name, length, &d), std::string("dimension ") + name);
    return d;
  }
  void text(int var, const char* name, const std::string& value) {
    check(nc_put_att_text(id_, var, name, value.size(), value.c_str()), std::string("attribute ") + name);
  }
  int variable(const char* name, std::initializer_list<int> dims) {
    int v = -1;
    std::vector<int> d(dims);
    check(nc_def_var(id_, name, NC_DOUBLE, static_cast<int>(d.size()), d.data(), &v),
          std::string("variable ") + name);
    check(nc_def_var_chunking(id_, v, NC_CONTIGUOUS, nullptr), std::string("layout of ") + name);
    return v;
  }
  void put(int var, const std::vector<double>& values) {
    check(nc_put_var_double(id_, var, values.data()), "write data");
  }
  void close() {
    const int id = id_;
    id_ = -1;
    check(nc_close(id), "close");
  }

 private:
  fs::path path_;
  int id_ = -1;
};

// Head frame -> room frame: the listener's position plus the rotation by the heading.
Eigen::Vector3d room_position(const SofaMetadata& meta, double azimuth_deg, double distance_m) {
  const double a = (meta.heading_deg + azimuth_deg) * kPi / 180.0;
  return meta.listener + distance_m * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
}

void write_globals(NetcdfFile& f, const SofaMetadata& meta) {
  const std::pair<const char*, std::string> globals[] = {
      {"Conventions", "SOFA"},
      {"Version", "2.1"},
      {"SOFAConventions", "SingleRoomMIMOSRIR"},
      {"SOFAConventionsVersion", "1.0"},
      {"DataType", "FIR-E"},
      {"RoomType", "shoebox"},
      {"Title", meta.title},
      // Fixed dates: a file sonomap writes is the same bytes on every run.
      {"DateCreated", "1970-01-01 00:00:00"},
      {"DateModified", "1970-01-01 00:00:00"},
      {"APIName", "sonomap"},
      {"APIVersion", "0.1"},
      {"AuthorContact", meta.author_contact},
      {"Organization", meta.organization},
      {"License", "GPL-3.0-or-later"},
      {"ApplicationName", "sonomap brir"},
      {"ApplicationVersion", "0.1"},
      {"Comment", meta.comment},
      {"History", "synthesised by the image-source method with a noise late tail"},
      {"References", "Allen and Berkley 1979"},
      {"Origin", "synthetic"},
      {"DatabaseName", "sonomap"},
      {"RoomDescription", "shoebox room of the image-source model"},
      {"ListenerShortName", "KEMAR"},
      {"ListenerDescription", "head of the HRIR set the responses were synthesised from"},
      {"SourceDescription", "one source per measurement, on the listener's horizontal plane"}};
  for (const auto& [name, value] : globals) f.text(NC_GLOBAL, name, value);
}

// AES69-2020 SingleRoomMIMOSRIR 1.0: one measurement per source position (M), two receivers
// (the ears, R), one emitter per source (E), positions in room coordinates.
void write_sofa_file(const fs::path& path, double sample_rate, double distance_m,
                            const std::vector<double>& azimuths,
                            const std::vector<audio::BinauralIr>& irs, const SofaMetadata& meta) {
  if (azimuths.empty() || azimuths.size() != irs.size())
    throw std::invalid_argument("write SOFA: need one IR per azimuth");
  const size_t m = irs.size(), n = irs.front().left.size();
  for (const auto& ir : irs)
    if (ir.left.size() != n || ir.right.size() != n || n == 0)
      throw std::invalid_argument("write SOFA: IRs of different lengths");
  NetcdfFile f(path);
  write_globals(f, meta);

  const int I = f.dim("I", 1), C = f.dim("C", 3), R = f.dim("R", 2), E = f.dim("E", 1);
  const int N = f.dim("N", n), M = f.dim("M", m);
  auto position = [&](const char* name, std::initializer_list<int> dims) {
    const int v = f.variable(name, dims);
    f.text(v, "Type", "cartesian");
    f.text(v, "Units", "metre");
    return v;
  };
  const int listener = position("ListenerPosition", {I, C});
  const int view = position("ListenerView", {I, C});
  const int up = f.variable("ListenerUp", {I, C});
  const int receiver = position("ReceiverPosition", {R, C, I});
  const int source = position("SourcePosition", {M, C});
  const int source_view = position("SourceView", {M, C});
  const int source_up = f.variable("SourceUp", {I, C});
  const int emitter = position("EmitterPosition", {E, C, I});
  const bool has_room = meta.room_min.allFinite() && meta.room_max.allFinite();
  int corner_a = -1, corner_b = -1;
  if (has_room) {
    const int corners = f.variable("RoomCorners", {I});
    f.text(corners, "Type", "cartesian");
    f.text(corners, "Units", "metre");
    corner_a = f.variable("RoomCornerA", {I, C});
    corner_b = f.variable("RoomCornerB", {I, C});
  }
  const int ir = f.variable("Data.IR", {M, R, N, E});
  const int rate = f.variable("Data.SamplingRate", {I});
  f.text(rate, "Units", "hertz");
  const int delay = f.variable("Data.Delay", {I, R, E});
  f.check(nc_enddef(f.id()), "end of definitions");

  const Eigen::Vector3d l = meta.listener;
  const double h = meta.heading_deg * kPi / 180.0;
  f.put(listener, {l.x(), l.y(), l.z()});
  f.put(view, {std::cos(h), std::sin(h), 0});
  f.put(up, {0, 0, 1});
  f.put(receiver, {0, 0.09, 0, 0, -0.09, 0});  // left ear +y, right ear -y (listener frame)
  std::vector<double> positions, views;
  for (double a : azimuths) {
    const Eigen::Vector3d p = room_position(meta, a, distance_m), towards = (l - p).normalized();
    positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    views.insert(views.end(), {towards.x(), towards.y(), towards.z()});  // facing the head
  }
  f.put(source, positions);
  f.put(source_view, views);
  f.put(source_up, {0, 0, 1});
  f.put(emitter, {0, 0, 0});
  if (has_room) {
    f.put(corner_a, {meta.room_min.x(), meta.room_min.y(), meta.room_min.z()});
    f.put(corner_b, {meta.room_max.x(), meta.room_max.y(), meta.room_max.z()});
  }
  std::vector<double> data;
  data.reserve(m * 2 * n);
  for (const auto& pair : irs) {
    data.insert(data.end(), pair.left.begin(), pair.left.end());
    data.insert(data.end(), pair.right.begin(), pair.right.end());
  }
  f.put(ir, data);
  f.put(rate, {sample_rate});
  f.put(delay, {0, 0});
  f.close();
}

const NetcdfFunctions kFunctions{open_status, status_text, write_sofa_file};

}  // namespace

}  // namespace sonomap::harness

extern "C" const sonomap::harness::NetcdfFunctions* sonomap_netcdf_functions() {
  return &sonomap::harness::kFunctions;
}
