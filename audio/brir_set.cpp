// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/brir_set.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sonomap::audio {

double wrap_degrees_180(double degrees) {
  double a = std::fmod(degrees, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

static bool all_finite(const std::vector<float>& v) {
  for (float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

size_t HrirSet::nearest(const Eigen::Vector3d& direction) const {
  if (directions.empty()) throw std::invalid_argument("HrirSet::nearest: empty HRIR set");
  const Eigen::Vector3d d = direction.normalized();
  size_t best = 0;
  double best_dot = -2.0;
  for (size_t i = 0; i < directions.size(); ++i) {
    const double dot = directions[i].dot(d);
    if (dot > best_dot) best_dot = dot, best = i;
  }
  return best;
}

void HrirSet::validate() const {
  if (!(sample_rate > 0.0) || !std::isfinite(sample_rate))
    throw std::invalid_argument("HRIR set: sample rate must be positive, got " +
                                std::to_string(sample_rate));
  if (directions.empty() || directions.size() != irs.size())
    throw std::invalid_argument("HRIR set: needs one IR per direction (got " +
                                std::to_string(directions.size()) + " directions, " +
                                std::to_string(irs.size()) + " IRs)");
  const size_t n = irs.front().left.size();
  for (size_t i = 0; i < irs.size(); ++i) {
    if (n == 0 || irs[i].left.size() != n || irs[i].right.size() != n)
      throw std::invalid_argument("HRIR set: IR " + std::to_string(i) + " has a different length");
    if (!all_finite(irs[i].left) || !all_finite(irs[i].right))
      throw std::invalid_argument("HRIR set: IR " + std::to_string(i) + " is not finite");
    if (!directions[i].allFinite() || directions[i].norm() < 1e-9)
      throw std::invalid_argument("HRIR set: direction " + std::to_string(i) + " is invalid");
  }
}

BrirGrid BrirGrid::paper() {
  BrirGrid g;
  for (int a = -177; a <= 180; a += 3) g.azimuths_deg.push_back(a);
  for (int d = 1; d <= 10; ++d) g.distances_m.push_back(0.4 * d);
  return g;
}

BrirSet::BrirSet(double sample_rate, BrirGrid grid, std::vector<BinauralIr> irs)
    : sample_rate_(sample_rate), grid_(std::move(grid)), irs_(std::move(irs)) {
  if (!(sample_rate_ > 0.0) || !std::isfinite(sample_rate_))
    throw std::invalid_argument("BRIR set: sample rate must be positive");
  if (grid_.azimuths_deg.empty() || grid_.distances_m.empty())
    throw std::invalid_argument("BRIR set: the grid needs at least one azimuth and one distance");
  if (irs_.size() != grid_.azimuths_deg.size() * grid_.distances_m.size())
    throw std::invalid_argument("BRIR set: " + std::to_string(irs_.size()) + " IRs for a grid of " +
                                std::to_string(grid_.azimuths_deg.size()) + " azimuths x " +
                                std::to_string(grid_.distances_m.size()) + " distances");
  for (double d : grid_.distances_m)
    if (!(d > 0.0) || !std::isfinite(d))
      throw std::invalid_argument("BRIR set: distances must be positive");
  ir_length_ = irs_.front().left.size();
  for (size_t i = 0; i < irs_.size(); ++i) {
    if (ir_length_ == 0 || irs_[i].left.size() != ir_length_ ||
        irs_[i].right.size() != ir_length_)
      throw std::invalid_argument("BRIR set: IR " + std::to_string(i) +
                                  " is empty or differs in length");
    if (!all_finite(irs_[i].left) || !all_finite(irs_[i].right))
      throw std::invalid_argument("BRIR set: IR " + std::to_string(i) + " is not finite");
  }
}

BrirSet::BrirSet(double sample_rate, BrirGrid grid, size_t ir_length, MakeIr make)
    : sample_rate_(sample_rate), grid_(std::move(grid)), ir_length_(ir_length), make_(std::move(make)) {
  if (!(sample_rate_ > 0.0) || !std::isfinite(sample_rate_))
    throw std::invalid_argument("BRIR set: sample rate must be positive");
  if (grid_.azimuths_deg.empty() || grid_.distances_m.empty())
    throw std::invalid_argument("BRIR set: the grid needs at least one azimuth and one distance");
  if (ir_length_ == 0 || !make_) throw std::invalid_argument("BRIR set: no response length or maker");
  irs_.resize(grid_.azimuths_deg.size() * grid_.distances_m.size());
  made_ = std::make_unique<std::once_flag[]>(irs_.size());
}

size_t BrirSet::made_count() const {
  size_t n = 0;
  for (const BinauralIr& ir : irs_) n += !ir.left.empty();
  return n;
}

size_t nearest_distance_index(const std::vector<double>& values, double metres) {
  if (values.empty()) throw std::invalid_argument("nearest distance: empty grid");
  constexpr double kTie = 1e-6;
  size_t best = 0;
  for (size_t i = 1; i < values.size(); ++i) {
    const double diff = std::abs(metres - values[i]), best_diff = std::abs(metres - values[best]);
    if (diff < best_diff - kTie || (diff <= best_diff + kTie && values[i] > values[best])) best = i;
  }
  return best;
}

size_t nearest_azimuth_index(const std::vector<double>& values, double degrees) {
  if (values.empty()) throw std::invalid_argument("nearest azimuth: empty grid");
  size_t best = 0;
  double best_diff = 1e9;
  for (size_t i = 0; i < values.size(); ++i) {
    const double diff = std::abs(wrap_degrees_180(degrees - values[i]));
    if (diff < best_diff - 1e-9) best_diff = diff, best = i;
  }
  return best;
}

size_t BrirSet::nearest_azimuth(double azimuth_deg) const {
  return nearest_azimuth_index(grid_.azimuths_deg, azimuth_deg);
}

size_t BrirSet::nearest_distance(double metres) const {
  return nearest_distance_index(grid_.distances_m, metres);
}

const BinauralIr& BrirSet::at(size_t distance_index, size_t azimuth_index) const {
  if (distance_index >= distance_count() || azimuth_index >= azimuth_count())
    throw std::invalid_argument("BRIR set: index out of range");
  const size_t i = distance_index * azimuth_count() + azimuth_index;
  if (made_) {
    std::call_once(made_[i], [&] {
      BinauralIr ir = make_(distance_index, azimuth_index);
      if (ir.left.size() != ir_length_ || ir.right.size() != ir_length_ || !all_finite(ir.left) ||
          !all_finite(ir.right))
        throw std::logic_error("BRIR set: a response made on demand has the wrong length or is not finite");
      // Each slot is written once, under its own flag, before any reader of that slot returns.
      irs_[i] = std::move(ir);
    });
  }
  return irs_[i];
}

double loudest_ear_energy(const BinauralIr& ir) {
  double loudest = 0.0;
  for (const auto* ear : {&ir.left, &ir.right}) {
    double energy = 0.0;
    for (float x : *ear) energy += double(x) * x;
    loudest = std::max(loudest, energy);
  }
  return loudest;
}

void scale(BinauralIr& ir, double factor) {
  for (auto* ear : {&ir.left, &ir.right})
    for (float& x : *ear) x = static_cast<float>(x * factor);
}

double BrirSet::normalise_to_reference() {
  if (made_) throw std::logic_error("BRIR set: a set made on demand is normalised by its maker");
  double loudest = 0.0;
  for (const BinauralIr& ir : irs_) loudest = std::max(loudest, loudest_ear_energy(ir));
  if (!(loudest > 0.0)) return 1.0;
  const double factor = 1.0 / std::sqrt(loudest);
  for (BinauralIr& ir : irs_) scale(ir, factor);
  return factor;
}

}  // namespace sonomap::audio
