// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/formats/sofa_io.hpp"

#include "audio/resample.hpp"
#include "harness/formats/modules.hpp"
#include "harness/support/errors.hpp"
#include "harness/support/output.hpp"
#include "harness/support/subprocess.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mysofa.h>

namespace fs = std::filesystem;

namespace sonomap::harness {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string mysofa_error_name(int err) {
  switch (err) {
    case MYSOFA_INTERNAL_ERROR: return "internal error";
    case MYSOFA_INVALID_FORMAT: return "invalid format";
    case MYSOFA_UNSUPPORTED_FORMAT: return "unsupported format";
    case MYSOFA_NO_MEMORY: return "out of memory";
    case MYSOFA_READ_ERROR: return "read error";
    case MYSOFA_INVALID_ATTRIBUTES: return "invalid attributes (need SimpleFreeFieldHRIR, FIR)";
    case MYSOFA_INVALID_DIMENSIONS: return "invalid dimensions";
    case MYSOFA_INVALID_DIMENSION_LIST: return "invalid dimension list";
    case MYSOFA_INVALID_COORDINATE_TYPE: return "invalid coordinate type";
    case MYSOFA_ONLY_EMITTER_WITH_ECI_SUPPORTED: return "unsupported emitter layout";
    case MYSOFA_ONLY_DELAYS_WITH_IR_OR_MR_SUPPORTED: return "unsupported delay layout";
    case MYSOFA_ONLY_THE_SAME_SAMPLING_RATE_SUPPORTED: return "several sampling rates";
    case MYSOFA_RECEIVERS_WITH_RCI_SUPPORTED: return "unsupported receiver layout";
    case MYSOFA_RECEIVERS_WITH_CARTESIAN_SUPPORTED: return "receivers must be cartesian";
    case MYSOFA_INVALID_RECEIVER_POSITIONS: return "invalid receiver positions";
    case MYSOFA_ONLY_SOURCES_WITH_MC_SUPPORTED: return "unsupported source layout";
    default: return "error " + std::to_string(err);
  }
}

struct HrtfDeleter {
  void operator()(MYSOFA_HRTF* h) const { mysofa_free(h); }
};

[[noreturn]] void bad(const fs::path& file, const std::string& what) {
  throw InputError(file.string(), 0, "", what);
}

std::string attribute(const MYSOFA_HRTF& h, const char* name) {
  const char* v = mysofa_getAttribute(h.attributes, const_cast<char*>(name));
  return v ? v : "";
}

// What sonomap needs of a SingleRoomMIMOSRIR file (mysofa_check knows SimpleFreeFieldHRIR only):
// impulse responses at two ears from one emitter per source, one listener with a view.
int check_room_layout(const MYSOFA_HRTF& h) {
  if (attribute(h, "DataType") != "FIR-E") return MYSOFA_INVALID_ATTRIBUTES;
  if (h.C != 3 || h.I != 1 || h.E != 1 || h.R != 2) return MYSOFA_INVALID_DIMENSIONS;
  for (const MYSOFA_ARRAY* a : {&h.ListenerPosition, &h.ListenerView})
    if (!a->values || a->elements != 3) return MYSOFA_INVALID_FORMAT;
  if (h.ListenerUp.values && h.ListenerUp.elements != 3) return MYSOFA_INVALID_FORMAT;
  return MYSOFA_OK;
}

Eigen::Vector3d array3(const MYSOFA_ARRAY& a) { return {a.values[0], a.values[1], a.values[2]}; }

// Rows: the listener's front, left and up axes in room coordinates (cartesian by now).
Eigen::Matrix3d head_frame(const MYSOFA_HRTF& h) {
  const Eigen::Vector3d up_hint = h.ListenerUp.values ? array3(h.ListenerUp) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d front = array3(h.ListenerView).normalized();
  const Eigen::Vector3d left = up_hint.cross(front).normalized();
  Eigen::Matrix3d m;
  m.row(0) = front;
  m.row(1) = left;
  m.row(2) = front.cross(left);
  return m;  // NaN when view and up are parallel or zero
}

// Debian's HDF5 1.10 frees an invalid pointer on some corrupt files (found by the sanitizer
// suite on a mutated default.sofa) and libmysofa can loop on others: the file is first opened
// by both readers in a child process, so a crash or a hang there becomes a clear error here.
// netCDF (loaded only in the child, when the file opens: modules.hpp) checks the container
// before libmysofa reads it: libmysofa 1.3.1 can loop for minutes on a corrupt HDF5 file that
// netCDF's HDF5 reader refuses at once (found by fuzz/fuzz_sofa). Returns whether both open it.
bool screen_in_child(const fs::path& file) {
  constexpr int kOpens = 0, kRefused = 10, kNoNetcdf = 11;
  return screen_file(file, "the SOFA readers (HDF5, libmysofa)", [&] {
           try {
             if (netcdf_functions().open_status(file) != 0) return kRefused;
           } catch (const std::runtime_error&) {
             return kNoNetcdf;  // the parent loads it again and says why it cannot
           }
           int err = 0;
           MYSOFA_HRTF* hrtf = mysofa_load(file.c_str(), &err);
           if (hrtf) mysofa_free(hrtf);
           return hrtf && err == MYSOFA_OK ? kOpens : kRefused;
         }) == kOpens;
}

}  // namespace

SofaContents read_sofa(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) bad(file, "not a readable file");
  // A file the child's readers refused cleanly is refused again here, with their message:
  // netCDF's first, so that libmysofa never reads a container netCDF refuses.
  if (!screen_in_child(file)) {
    const NetcdfFunctions& netcdf = netcdf_functions();
    if (const int status = netcdf.open_status(file); status != 0)
      bad(file, "not a SOFA (netCDF-4/HDF5) file: " + netcdf.status_text(status));
  }
  int err = 0;
  std::unique_ptr<MYSOFA_HRTF, HrtfDeleter> hrtf(mysofa_load(file.c_str(), &err));
  if (!hrtf || err != MYSOFA_OK) bad(file, "libmysofa cannot load it: " + mysofa_error_name(err));
  const std::string conventions = attribute(*hrtf, "SOFAConventions");
  const bool room = conventions == "SingleRoomMIMOSRIR";
  err = room ? check_room_layout(*hrtf) : mysofa_check(hrtf.get());
  if (err != MYSOFA_OK) bad(file, "not a usable SOFA HRIR/BRIR file: " + mysofa_error_name(err));
  mysofa_tocartesian(hrtf.get());

  const MYSOFA_HRTF& h = *hrtf;
  const size_t m = h.M, r = h.R, n = h.N;
  if (m == 0 || r != 2 || n == 0) bad(file, "needs M > 0 measurements, 2 receivers, N > 0 samples");
  if (!h.DataIR.values || h.DataIR.elements != m * r * n)
    bad(file, "Data.IR holds " + std::to_string(h.DataIR.elements) + " values, expected M*R*N = " +
                  std::to_string(m * r * n));
  if (!h.SourcePosition.values || h.SourcePosition.elements != m * 3)
    bad(file, "SourcePosition must hold M x 3 values");
  if (!h.DataSamplingRate.values || h.DataSamplingRate.elements < 1)
    bad(file, "Data.SamplingRate is missing");
  const double rate = h.DataSamplingRate.values[0];
  if (!std::isfinite(rate) || rate < 8000.0 || rate > 384000.0)
    bad(file, "Data.SamplingRate " + std::to_string(rate) + " Hz is outside [8000, 384000]");

  // Data.Delay (dims I,R or M,R) in samples: applied as whole samples in front of the IR.
  std::vector<size_t> delay(m * 2, 0);
  if (h.DataDelay.values) {
    const size_t e = h.DataDelay.elements;
    if (e != 2 && e != m * 2) bad(file, "Data.Delay must hold R or M x R values");
    for (size_t i = 0; i < m * 2; ++i) {
      const double d = h.DataDelay.values[e == 2 ? i % 2 : i];
      if (!std::isfinite(d) || d < 0.0 || d > rate) bad(file, "Data.Delay out of [0, 1 s]");
      delay[i] = static_cast<size_t>(std::lround(d));
    }
  }
  const size_t longest = n + *std::max_element(delay.begin(), delay.end());

  SofaContents out;
  out.sample_rate = rate;
  out.conventions = conventions;
  out.room_type = attribute(h, "RoomType");
  for (const MYSOFA_ATTRIBUTE* a = h.attributes; a; a = a->next)
    if (a->name) out.attributes[a->name] = a->value ? a->value : "";
  const Eigen::Matrix3d to_head = room ? head_frame(h) : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d head = room ? array3(h.ListenerPosition) : Eigen::Vector3d::Zero();
  if (!to_head.allFinite() || !head.allFinite())
    bad(file, "ListenerPosition/ListenerView/ListenerUp do not give the head's position and axes");
  out.source_positions.reserve(m);
  out.irs.reserve(m);
  for (size_t i = 0; i < m; ++i) {
    const float* p = h.SourcePosition.values + 3 * i;
    out.source_positions.push_back(to_head * (Eigen::Vector3d(p[0], p[1], p[2]) - head));
    if (!out.source_positions.back().allFinite())
      bad(file, "SourcePosition of measurement " + std::to_string(i) + " is not finite");
    audio::BinauralIr ir{std::vector<float>(longest, 0.0f), std::vector<float>(longest, 0.0f)};
    for (size_t ear = 0; ear < 2; ++ear) {
      const float* src = h.DataIR.values + (i * r + ear) * n;
      auto& dst = ear == 0 ? ir.left : ir.right;
      for (size_t k = 0; k < n; ++k) {
        if (!std::isfinite(src[k]))
          bad(file, "Data.IR of measurement " + std::to_string(i) + " is not finite");
        dst[delay[2 * i + ear] + k] = src[k];
      }
    }
    out.irs.push_back(std::move(ir));
  }
  return out;
}

static audio::BinauralIr resampled(const audio::BinauralIr& ir, double ratio) {
  if (ratio == 1.0) return ir;
  audio::BinauralIr out{audio::resample(ir.left, ratio), audio::resample(ir.right, ratio)};
  const size_t n = std::max(out.left.size(), out.right.size());
  out.left.resize(n, 0.0f);
  out.right.resize(n, 0.0f);
  return out;
}

audio::HrirSet read_hrir_set(const fs::path& file, double output_rate) {
  SofaContents sofa = read_sofa(file);
  audio::HrirSet set;
  set.sample_rate = output_rate;
  const double ratio = output_rate / sofa.sample_rate;
  for (size_t i = 0; i < sofa.irs.size(); ++i) {
    if (sofa.source_positions[i].norm() < 1e-9) bad(file, "a source sits at the listener");
    set.directions.push_back(sofa.source_positions[i].normalized());
    set.irs.push_back(resampled(sofa.irs[i], ratio));
  }
  try {
    set.validate();
  } catch (const std::invalid_argument& e) {
    bad(file, e.what());
  }
  return set;
}

namespace {

// One BRIR file's measurements on the horizontal plane (one distance), by azimuth.
struct Layer {
  double distance = -1.0;
  std::vector<double> azimuths;
  std::vector<audio::BinauralIr> irs;  // in the order of `azimuths`
};

Layer horizontal_layer(const fs::path& file, const SofaContents& sofa) {
  Layer layer;
  for (size_t i = 0; i < sofa.irs.size(); ++i) {
    const Eigen::Vector3d& p = sofa.source_positions[i];
    const double horizontal = p.head<2>().norm();
    const double elevation = std::atan2(p.z(), horizontal) * 180.0 / kPi;
    if (std::abs(elevation) >= 1.0) continue;
    const double distance = p.norm();
    if (layer.distance < 0.0) layer.distance = distance;
    if (std::abs(distance - layer.distance) > 0.01)
      bad(file, "holds several distances (" + std::to_string(layer.distance) + " and " +
                    std::to_string(distance) + " m); write one file per distance");
    layer.azimuths.push_back(std::atan2(p.y(), p.x()) * 180.0 / kPi);
    layer.irs.push_back(sofa.irs[i]);
  }
  if (layer.irs.empty()) bad(file, "no measurement on the horizontal plane");
  return layer;
}

// The layer's responses reordered to `azimuths` (the first file's); the same azimuths or bad input.
void reorder_to(Layer& layer, const std::vector<double>& azimuths, const fs::path& file) {
  if (layer.azimuths.size() != azimuths.size())
    bad(file, std::to_string(layer.azimuths.size()) + " horizontal azimuths, the first file has " +
                  std::to_string(azimuths.size()));
  std::vector<audio::BinauralIr> ordered;
  for (double a : azimuths) {
    size_t j = 0;
    while (j < layer.azimuths.size() && std::abs(audio::wrap_degrees_180(layer.azimuths[j] - a)) > 0.01) ++j;
    if (j == layer.azimuths.size()) bad(file, "has no measurement at azimuth " + std::to_string(a) + " degrees");
    ordered.push_back(std::move(layer.irs[j]));
  }
  layer.irs = std::move(ordered);
  layer.azimuths = azimuths;
}

void check_distances(const fs::path& directory, const std::vector<Layer>& layers,
                     const std::vector<double>& required) {
  for (double d : required) {
    const bool found = std::any_of(layers.begin(), layers.end(),
                                   [&](const Layer& l) { return std::abs(l.distance - d) < 0.01; });
    if (!found) {
      std::string have;
      for (const auto& l : layers) have += (have.empty() ? "" : ", ") + std::to_string(l.distance);
      bad(directory, "missing BRIRs for distance " + std::to_string(d) + " m (have: " + have + ")");
    }
  }
}

// The layers as one set at `output_rate`, nearest first, every response padded to the longest.
audio::BrirSet assemble(const fs::path& directory, std::vector<Layer> layers, double rate, double output_rate) {
  std::sort(layers.begin(), layers.end(), [](const Layer& a, const Layer& b) { return a.distance < b.distance; });
  size_t length = 0;
  for (const auto& layer : layers) length = std::max(length, layer.irs.front().left.size());
  audio::BrirGrid grid;
  grid.azimuths_deg = layers.front().azimuths;
  std::vector<audio::BinauralIr> irs;
  const double ratio = output_rate / rate;
  for (auto& layer : layers) {
    grid.distances_m.push_back(layer.distance);
    for (auto& ir : layer.irs) {
      ir.left.resize(length, 0.0f);  // files of different lengths: pad with silence
      ir.right.resize(length, 0.0f);
      irs.push_back(resampled(ir, ratio));
    }
  }
  try {
    return audio::BrirSet(output_rate, std::move(grid), std::move(irs));
  } catch (const std::invalid_argument& e) {
    bad(directory, e.what());
  }
}

}  // namespace

audio::BrirSet read_brir_directory(const fs::path& directory, double output_rate,
                                   const std::vector<double>& required) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) bad(directory, "not a directory");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory, ec))
    if (entry.path().extension() == ".sofa") files.push_back(entry.path());
  if (ec) bad(directory, "cannot list: " + ec.message());
  if (files.empty()) bad(directory, "no .sofa files (expected one BRIR file per distance)");
  std::sort(files.begin(), files.end());

  std::vector<Layer> layers;
  double rate = 0.0;
  for (const fs::path& file : files) {
    const SofaContents sofa = read_sofa(file);
    if (rate == 0.0) rate = sofa.sample_rate;
    else if (std::abs(sofa.sample_rate - rate) > 1e-6)
      bad(file, "sample rate " + std::to_string(sofa.sample_rate) + " Hz differs from " +
                    std::to_string(rate) + " Hz of " + files.front().filename().string());
    Layer layer = horizontal_layer(file, sofa);
    if (!layers.empty()) reorder_to(layer, layers.front().azimuths, file);
    for (const auto& other : layers)
      if (std::abs(other.distance - layer.distance) < 0.01)
        bad(file, "a second file for distance " + std::to_string(layer.distance) + " m");
    layers.push_back(std::move(layer));
  }
  check_distances(directory, layers, required);
  return assemble(directory, std::move(layers), rate, output_rate);
}

std::string brir_file_name(double distance_m) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "brir_%.2fm.sofa", distance_m);
  return buf;
}

void write_brir_sofa(const fs::path& file, double sample_rate, double distance_m,
                     const std::vector<double>& azimuths_deg,
                     const std::vector<audio::BinauralIr>& irs, const SofaMetadata& meta) {
  StagedFile staged(file);
  netcdf_functions().write_brir_sofa(staged.path(), sample_rate, distance_m, azimuths_deg, irs, meta);
  staged.commit();
}

void write_brir_directory(const fs::path& directory, const audio::BrirSet& set,
                          const SofaMetadata& meta) {
  StagedDirectory staged(directory, "brir");
  const size_t na = set.azimuth_count();
  for (size_t d = 0; d < set.distance_count(); ++d) {
    std::vector<audio::BinauralIr> irs;
    for (size_t a = 0; a < na; ++a) irs.push_back(set.at(d, a));
    const double distance = set.grid().distances_m[d];
    netcdf_functions().write_brir_sofa(staged.path() / brir_file_name(distance), set.sample_rate(),
                                       distance, set.grid().azimuths_deg, irs, meta);
  }
  staged.commit();
}

}  // namespace sonomap::harness
