// SPDX-License-Identifier: GPL-3.0-or-later
// SOFA (AES69) files <-> the in-memory impulse-response sets of audio/.
// Reading uses libmysofa's low-level path (mysofa_load + mysofa_check): no loudness
// normalisation and no interpolation; every measured IR is taken as stored (Data.Delay applied
// as whole samples) and resampled to the output rate with libsamplerate when the file's differs.
// Writing uses the netCDF-4 C API (in harness/netcdf/, loaded on demand), AES69's convention
// for room responses, SingleRoomMIMOSRIR 1.0
// (DataType FIR-E, RoomType shoebox, positions in room coordinates), in the layout libmysofa
// 1.3.1 loads: Data.IR contiguous and uncompressed, Data.Delay present, no timestamps.
// Read back: SimpleFreeFieldHRIR (checked by mysofa_check) or SingleRoomMIMOSRIR (checked
// here: two ears, one emitter), source positions turned into the listener's head frame.
// Bad files raise InputError naming the file.
#pragma once

#include "audio/brir_set.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace sonomap::harness {

// One SOFA file as stored: measurement positions (cartesian, head frame) and binaural IRs.
struct SofaContents {
  double sample_rate = 0.0;
  std::vector<Eigen::Vector3d> source_positions;  // metres, head frame: x front, y left, z up
  std::vector<audio::BinauralIr> irs;
  std::string conventions;  // SOFAConventions
  std::string room_type;
  std::map<std::string, std::string> attributes;  // every global attribute, as stored
};

// Reads a SimpleFreeFieldHRIR or SingleRoomMIMOSRIR file libmysofa loads. No resampling.
SofaContents read_sofa(const std::filesystem::path& file);

// An HRIR set for synthesis, resampled to `output_rate`.
audio::HrirSet read_hrir_set(const std::filesystem::path& file, double output_rate);

// A BRIR set from a directory of SOFA files, one file per distance (any names ending .sofa).
// Only horizontal measurements (|elevation| < 1 degree) are used; every file must hold the same
// azimuths at one distance and share one sample rate; every distance of `required` must be
// present (within 1 cm). Resampled to `output_rate`.
audio::BrirSet read_brir_directory(const std::filesystem::path& directory, double output_rate,
                                   const std::vector<double>& required_distances_m =
                                       audio::BrirGrid::paper().distances_m);

// What a written BRIR file says besides its responses (AES69 attributes and positions).
struct SofaMetadata {
  std::string title = "sonomap synthetic BRIR";
  std::string comment;
  std::string author_contact = "whoever ran sonomap brir (generated file)";
  std::string organization = "sonomap";
  // The room (RoomCornerA/B; not written when NaN) and the head in it, facing heading_deg
  // from +x: source positions are written in these room coordinates.
  Eigen::Vector3d room_min = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d room_max = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d listener = Eigen::Vector3d::Zero();
  double heading_deg = 0.0;
};

// Writes one SOFA file: measurements from `azimuths_deg` (elevation 0) at `distance_m`.
// Written to a temporary name and renamed: the file appears whole or not at all.
void write_brir_sofa(const std::filesystem::path& file, double sample_rate, double distance_m,
                     const std::vector<double>& azimuths_deg,
                     const std::vector<audio::BinauralIr>& irs, const SofaMetadata& meta = {});

// The file name used for one distance of a set: "brir_0.40m.sofa".
std::string brir_file_name(double distance_m);

// Writes a whole set, one file per distance, into `directory` (created atomically: a staged
// directory renamed into place; an existing directory is replaced).
void write_brir_directory(const std::filesystem::path& directory, const audio::BrirSet& set,
                          const SofaMetadata& meta = {});

}  // namespace sonomap::harness
