// SPDX-License-Identifier: GPL-3.0-or-later
#include "audio/brir_synth.hpp"

#include "audio/fft.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <tbb/parallel_for.h>

namespace sonomap::audio {

namespace {
constexpr double kPi = 3.14159265358979323846;
// 60 dB of decay: energy falls by 10^-6 = exp(-13.8155) over one RT60.
constexpr double kLn1e3 = 6.907755278982137;
constexpr int kFractionalTaps = 16;    // windowed-sinc fractional delay
constexpr double kTailFadeS = 0.005;   // tail fade-in at the mixing time
}  // namespace

double ShoeboxRoom::volume() const {
  const Eigen::Vector3d s = size();
  return s.x() * s.y() * s.z();
}

double ShoeboxRoom::surface() const {
  const Eigen::Vector3d s = size();
  return 2.0 * (s.x() * s.y() + s.x() * s.z() + s.y() * s.z());
}

// 0.161 s/m = 24 ln(10) / c at c = 343 m/s.
static constexpr double kSabine = 0.161;

double sabine_rt60(const ShoeboxRoom& room, double absorption) {
  return kSabine * room.volume() / (room.surface() * absorption);
}
double sabine_absorption(const ShoeboxRoom& room, double rt60) {
  return kSabine * room.volume() / (room.surface() * rt60);
}
double eyring_rt60(const ShoeboxRoom& room, double absorption) {
  return kSabine * room.volume() / (-room.surface() * std::log(1.0 - absorption));
}
double eyring_absorption(const ShoeboxRoom& room, double rt60) {
  return 1.0 - std::exp(-kSabine * room.volume() / (room.surface() * rt60));
}

const std::vector<double>& octave_band_centres() {
  static const std::vector<double> centres{125, 250, 500, 1000, 2000, 4000, 8000};
  return centres;
}

static void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("BRIR synthesis: " + what);
}

Eigen::Vector3d listener_position(const BrirSynthConfig& c) {
  if (!c.listener.hasNaN()) return c.listener;
  const Eigen::Vector3d centre = 0.5 * (c.room.min_corner + c.room.max_corner);
  const double height = std::min(1.5, 0.5 * c.room.size().z());
  return {centre.x(), centre.y(), c.room.min_corner.z() + height};
}

void validate(const BrirSynthConfig& c) {
  const Eigen::Vector3d s = c.room.size();
  require(c.room.min_corner.allFinite() && c.room.max_corner.allFinite() &&
              c.room.min_corner.cwiseAbs().maxCoeff() <= kRoomBounds.max_coordinate_m &&
              c.room.max_corner.cwiseAbs().maxCoeff() <= kRoomBounds.max_coordinate_m,
          "room corners must be finite and within 10 km of the origin");
  require((s.array() >= kRoomBounds.min_side_m).all() && (s.array() <= kRoomBounds.max_side_m).all(),
          "room sides must be in [1, 500] m, got " + std::to_string(s.x()) + " x " +
              std::to_string(s.y()) + " x " + std::to_string(s.z()));
  const Eigen::Vector3d l = listener_position(c);
  require(l.allFinite() && (l.array() > c.room.min_corner.array()).all() &&
              (l.array() < c.room.max_corner.array()).all(),
          "listener must be inside the room");
  const double wall = std::min((l - c.room.min_corner).minCoeff(), (c.room.max_corner - l).minCoeff());
  require(wall >= kRoomBounds.min_wall_distance_m,
          "listener must be at least 0.25 m from every wall, floor and ceiling (is " +
              std::to_string(wall) + " m)");
  const std::string rt60_range = "rt60 must be in (0.01, 3] s";
  require(std::isfinite(c.rt60) && c.rt60 > 0.01 && c.rt60 <= kRoomBounds.max_rt60_s,
          rt60_range + ", got " + std::to_string(c.rt60));
  require(c.band_rt60.empty() || c.band_rt60.size() == octave_band_centres().size(),
          "band_rt60 needs one value per octave band (7)");
  for (double t : c.band_rt60)
    require(std::isfinite(t) && t > 0.01 && t <= kRoomBounds.max_rt60_s, "band " + rt60_range);
  require(c.max_order >= 0 && c.max_order <= 30, "max_order must be in [0, 30]");
  require(std::isfinite(c.sample_rate) && c.sample_rate >= 8000 && c.sample_rate <= 384000,
          "sample rate must be in [8000, 384000] Hz");
  require(std::isfinite(c.length_s) && c.length_s >= 0.0 && c.length_s <= kRoomBounds.max_rt60_s,
          "length must be in [0, 3] s");
  require(std::isfinite(c.speed_of_sound) && c.speed_of_sound > 100.0, "speed of sound");
  require(std::isfinite(c.wall_margin) && c.wall_margin >= 0.0, "wall margin must be >= 0");
  require(std::isfinite(c.listener_heading_deg), "listener heading must be finite");
  // With Eyring, a 60 dB decay shorter than the room allows means absorption >= 1.
  require(eyring_absorption(c.room, c.rt60) < 0.999,
          "rt60 " + std::to_string(c.rt60) + " s is too short for this room");
}

namespace {

// Uniform noise of unit variance from our own stream (portable across standard libraries).
std::vector<float> unit_noise(size_t n, uint64_t seed, uint64_t stream) {
  // seed_seq takes 32-bit words: give it all 128 bits.
  std::seed_seq seq{uint32_t(seed), uint32_t(seed >> 32), uint32_t(stream), uint32_t(stream >> 32)};
  std::mt19937_64 rng(seq);
  std::vector<float> out(n);
  const double scale = std::sqrt(3.0);
  for (auto& x : out) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;  // [0, 1)
    x = static_cast<float>((2.0 * u - 1.0) * scale);
  }
  return out;
}

// Triangular weights in log frequency between neighbouring band centres: they sum to one.
double band_weight(double f, size_t band) {
  const auto& c = octave_band_centres();
  const double x = std::log2(std::max(f, 1.0));
  const double centre = std::log2(c[band]);
  if (band == 0 && x <= centre) return 1.0;
  if (band + 1 == c.size() && x >= centre) return 1.0;
  return std::max(0.0, 1.0 - std::abs(x - centre));  // octave spacing: neighbours 1 apart
}

// The octave bands of a late tail over `length` samples: each band's decay, exp(-ln(1000) t /
// RT60) (one envelope when all bands share their RT60), and, when they differ, each band's
// weight per bin of the transform that splits the noise into bands. The same for every
// source: made once per synthesizer.
struct TailBands {
  std::vector<std::vector<float>> envelopes;
  size_t split_size = 0;                    // the splitting transform's size (0: no split)
  std::vector<std::vector<float>> weights;  // per band, per bin of that transform
  TailBands(size_t length, double fs, const std::vector<double>& band_rt60) {
    const bool uniform = std::all_of(band_rt60.begin(), band_rt60.end(),
                                     [&](double t) { return t == band_rt60.front(); });
    envelopes.assign(uniform ? 1 : band_rt60.size(), std::vector<float>(length));
    for (size_t b = 0; b < envelopes.size(); ++b)
      for (size_t i = 0; i < length; ++i)
        envelopes[b][i] = static_cast<float>(std::exp(-kLn1e3 * (i / fs) / band_rt60[b]));
    if (uniform) return;
    split_size = next_power_of_two(length) * 2;
    weights.assign(envelopes.size(), std::vector<float>(split_size / 2 + 1));
    for (size_t b = 0; b < weights.size(); ++b)
      for (size_t k = 0; k < weights[b].size(); ++k)
        weights[b][k] = static_cast<float>(band_weight(k * fs / split_size, b));
  }
};

// Decaying noise: each octave band decays by its own envelope (TailBands).
std::vector<float> decaying_noise(const TailBands& bands, uint64_t seed, uint64_t stream) {
  const size_t length = bands.envelopes.front().size();
  std::vector<float> noise = unit_noise(length, seed, stream);
  std::vector<float> out(length, 0.0f);
  if (bands.envelopes.size() == 1) {
    for (size_t i = 0; i < length; ++i) out[i] = noise[i] * bands.envelopes.front()[i];
    return out;
  }
  const RealFft fft(bands.split_size);
  AlignedSamples time(fft.size(), 0.0f);
  std::copy(noise.begin(), noise.end(), time.begin());
  Spectrum spectrum(fft.bins()), band(fft.bins());
  fft.forward(time.data(), spectrum.data());
  for (size_t b = 0; b < bands.envelopes.size(); ++b) {
    for (size_t k = 0; k < fft.bins(); ++k) band[k] = spectrum[k] * bands.weights[b][k];
    fft.inverse(band.data(), time.data());
    for (size_t i = 0; i < length; ++i) out[i] += time[i] / fft.size() * bands.envelopes[b][i];
  }
  return out;
}

// Each bin of a spectrum lies between two twelfth-octave band centres: the lower one's index
// and the upper one's weight (the same for every frame of a tail: made once).
struct BandPlaces {
  size_t bands = 0;
  std::vector<std::pair<size_t, double>> of_bin;
  BandPlaces(double fs, size_t fft_size, size_t bins) {
    constexpr double kLowest = 50.0, kPerOctave = 12.0;
    bands = static_cast<size_t>(std::ceil(kPerOctave * std::log2(0.5 * fs / kLowest))) + 1;
    for (size_t k = 0; k < bins; ++k) {
      const double x = kPerOctave * std::log2(std::max(k * fs / fft_size, kLowest) / kLowest);
      const size_t b = std::min(static_cast<size_t>(x), bands - 1);
      of_bin.emplace_back(b, std::min(1.0, x - b));
    }
  }
};

// Gives two spectra the same energy in every twelfth of an octave (the mean of the two). The
// per-bin gains are smooth in frequency (triangular weights in log frequency): short filters.
void balance_spectra(Spectrum& l, Spectrum& r, const BandPlaces& places) {
  const size_t bands = places.bands;
  std::vector<double> el(bands + 1, 0.0), er(bands + 1, 0.0);
  for (size_t k = 0; k < l.size(); ++k) {
    const auto [b, w] = places.of_bin[k];
    el[b] += (1.0 - w) * std::norm(l[k]), el[b + 1] += w * std::norm(l[k]);
    er[b] += (1.0 - w) * std::norm(r[k]), er[b + 1] += w * std::norm(r[k]);
  }
  std::vector<double> gl(bands + 1, 1.0), gr(bands + 1, 1.0);
  for (size_t b = 0; b <= bands; ++b) {
    const double mean = 0.5 * (el[b] + er[b]);
    if (el[b] > 0.0 && er[b] > 0.0) gl[b] = std::sqrt(mean / el[b]), gr[b] = std::sqrt(mean / er[b]);
  }
  for (size_t k = 0; k < l.size(); ++k) {
    const auto [b, w] = places.of_bin[k];
    l[k] *= static_cast<float>((1.0 - w) * gl[b] + w * gl[b + 1]);
    r[k] *= static_cast<float>((1.0 - w) * gr[b] + w * gr[b + 1]);
  }
}

// The ear balancing's frames (below), their window and their bins' band places: they depend
// on the sample rate only, so each synthesizer makes them once.
struct EarBalance {
  size_t frame, hop, pad;  // the frame sits mid-buffer, `pad` from its start
  RealFft fft;
  std::vector<double> hann;  // periodic
  BandPlaces places;
  explicit EarBalance(double fs)
      : frame(next_power_of_two(static_cast<size_t>(0.04 * fs))), hop(frame / 2), pad(frame / 2),
        fft(2 * frame), hann(frame), places(fs, fft.size(), fft.bins()) {
    for (size_t i = 0; i < frame; ++i) hann[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * i / frame);
  }
};

// Gives the two ears' tails the same energy in every twelfth of an octave and every ~43 ms
// frame, as a diffuse field has at the ears of a symmetric head: two independent noises differ
// by several dB in a narrow band, which would make a source straight ahead lean to one side.
// Hann frames at 50% overlap (they sum to one), each balanced and added back whole (zero
// padded: the short balancing filters do not wrap around).
void balance_ears(std::vector<float>& left, std::vector<float>& right, const EarBalance& shape) {
  const size_t n = left.size();
  const size_t frame = shape.frame, hop = shape.hop, pad = shape.pad;
  const RealFft& fft = shape.fft;
  const std::vector<double>& hann = shape.hann;
  AlignedSamples time(fft.size());
  Spectrum l(fft.bins()), r(fft.bins());
  std::vector<float> out_l(n + 3 * frame, 0.0f), out_r(n + 3 * frame, 0.0f);
  auto analyse = [&](const std::vector<float>& x, long start, Spectrum& spectrum) {
    std::fill(time.begin(), time.end(), 0.0f);
    for (size_t i = 0; i < frame; ++i) {
      const long j = start + static_cast<long>(i);
      if (j >= 0 && j < static_cast<long>(n)) time[pad + i] = static_cast<float>(hann[i] * x[j]);
    }
    fft.forward(time.data(), spectrum.data());
  };
  auto add_back = [&](Spectrum& spectrum, std::vector<float>& out, long start) {
    fft.inverse(spectrum.data(), time.data());
    for (size_t i = 0; i < fft.size(); ++i) {
      // out starts at -(hop + pad): the filters spread either side of the frame
      const long j = start + static_cast<long>(i) + static_cast<long>(hop);
      if (j >= 0 && j < static_cast<long>(out.size())) out[j] += time[i] / fft.size();
    }
  };
  for (long start = -static_cast<long>(hop); start < static_cast<long>(n); start += hop) {
    analyse(left, start, l);
    analyse(right, start, r);
    balance_spectra(l, r, shape.places);
    add_back(l, out_l, start);
    add_back(r, out_r, start);
  }
  for (size_t i = 0; i < n; ++i) left[i] = out_l[i + hop + pad], right[i] = out_r[i + hop + pad];
}

// Noise streams of one source direction: each (azimuth, distance) and ear has its own.
uint64_t direction_stream(double azimuth_deg, double distance_m) {
  const auto az = static_cast<uint64_t>(std::llround((wrap_degrees_180(azimuth_deg) + 180.0) * 1000.0));
  const auto mm = static_cast<uint64_t>(std::llround(distance_m * 1000.0));
  return (az * 1000003u + mm) * 2u;
}

// One axis of the image lattice: coordinate of the image and its number of reflections.
struct AxisImage {
  double coordinate;
  int reflections;
};

std::vector<AxisImage> axis_images(double source, double lo, double hi, int max_order) {
  // Allen & Berkley: x = (1 - 2q) x' + 2 n L, reflections |n - q| + |n| (walls at 0 and L).
  const double length = hi - lo;
  const double x = source - lo;
  std::vector<AxisImage> out;
  for (int n = -max_order - 1; n <= max_order + 1; ++n)
    for (int q = 0; q <= 1; ++q) {
      const int count = std::abs(n - q) + std::abs(n);
      if (count <= max_order + 1) out.push_back({lo + (1 - 2 * q) * x + 2.0 * n * length, count});
    }
  return out;
}

}  // namespace

// What every late tail of one synthesizer shares: its octave bands and the ear balancing's
// frames (shared by copies of the synthesizer, not recomputed per source).
struct BrirSynthesizer::TailShape {
  TailBands bands;
  EarBalance balance;
};

BrirSynthesizer::BrirSynthesizer(HrirSet hrirs, BrirSynthConfig config)
    : hrirs_(std::move(hrirs)), config_(std::move(config)) {
  validate(config_);
  hrirs_.validate();
  if (std::abs(hrirs_.sample_rate - config_.sample_rate) > 1e-6)
    throw std::invalid_argument("BRIR synthesis: HRIR rate " + std::to_string(hrirs_.sample_rate) +
                                " Hz differs from the output rate " +
                                std::to_string(config_.sample_rate) + " Hz (resample first)");
  listener_ = listener_position(config_);
  absorption_ = eyring_absorption(config_.room, config_.rt60);
  std::vector<double> band_rt60 = config_.band_rt60;
  if (band_rt60.empty()) band_rt60.assign(octave_band_centres().size(), config_.rt60);
  const double longest = *std::max_element(band_rt60.begin(), band_rt60.end());
  // Given a length, keep it (synthesize refuses a source whose direct sound it would cut);
  // otherwise the longest RT60, and at least the direct sound of the paper grid's farthest source.
  if (config_.length_s > 0.0)
    length_ = static_cast<size_t>(std::ceil(config_.length_s * config_.sample_rate));
  else
    length_ = std::max(static_cast<size_t>(std::ceil(longest * config_.sample_rate)),
                       direct_end(BrirGrid::paper().distances_m.back()));
  if (config_.late_tail) {
    // Diffuse-field level: image sources arrive at 4 pi c^3 t^2 / V per second with energy
    // E_hrir / (c t)^2 each, i.e. 4 pi c E_hrir / V per second, decaying by the RT60.
    double hrir_energy = 0.0;
    for (const auto& ir : hrirs_.irs)
      for (size_t i = 0; i < ir.left.size(); ++i)
        hrir_energy += 0.5 * (double(ir.left[i]) * ir.left[i] + double(ir.right[i]) * ir.right[i]);
    hrir_energy /= hrirs_.irs.size();
    const double c = config_.speed_of_sound;
    tail_level_ = std::sqrt(4.0 * kPi * c * hrir_energy / (config_.room.volume() * config_.sample_rate));
  }
  tail_shape_ = std::make_shared<const TailShape>(
      TailShape{TailBands(length_, config_.sample_rate, band_rt60), EarBalance(config_.sample_rate)});
}

size_t BrirSynthesizer::direct_end(double distance_m) const {
  return static_cast<size_t>(std::ceil(distance_m / config_.speed_of_sound * config_.sample_rate)) +
         kFractionalTaps / 2 + hrirs_.irs.front().left.size();
}

// The late tail of one source from `start` on (faded in), its own noise per ear, ears balanced.
BinauralIr BrirSynthesizer::late_tail(double azimuth_deg, double distance_m, size_t start) const {
  const uint64_t stream = direction_stream(azimuth_deg, distance_m);
  BinauralIr tail{decaying_noise(tail_shape_->bands, config_.seed, stream),
                  decaying_noise(tail_shape_->bands, config_.seed, stream + 1)};
  const size_t fade = std::max<size_t>(1, static_cast<size_t>(kTailFadeS * config_.sample_rate));
  // A raised-cosine fade-in over `fade` samples from `start`: silent before, full after.
  auto gain = [&](double t) { return static_cast<float>(tail_level_ * (0.5 - 0.5 * std::cos(kPi * t))); };
  const float silent = gain(0.0), full = gain(1.0);
  auto window = [&](std::vector<float>& x) {
    for (size_t i = 0; i < length_; ++i)
      x[i] *= i < start ? silent : i - start >= fade ? full : gain(double(i - start) / fade);
  };
  window(tail.left);
  window(tail.right);
  balance_ears(tail.left, tail.right, tail_shape_->balance);
  for (size_t i = 0; i < std::min(start, length_); ++i) tail.left[i] = tail.right[i] = 0.0f;
  return tail;
}

void BrirSynthesizer::check_source(double azimuth_deg, double distance_m) const {
  if (!std::isfinite(azimuth_deg) || !std::isfinite(distance_m) || distance_m <= 0.05 ||
      distance_m > kRoomBounds.max_side_m)
    throw std::invalid_argument("BRIR synthesis: source azimuth/distance must be finite, in (0.05, 500] m");
  if (direct_end(distance_m) > length_)
    throw std::invalid_argument("BRIR synthesis: an IR of " + std::to_string(length_ / config_.sample_rate) +
                                " s cuts off the direct sound of a source at " + std::to_string(distance_m) +
                                " m (needs at least " + std::to_string(min_length_s(distance_m)) + " s)");
}

BinauralIr BrirSynthesizer::synthesize(double azimuth_deg, double distance_m) const {
  check_source(azimuth_deg, distance_m);
  const double heading = config_.listener_heading_deg * kPi / 180.0;
  const double world_angle = heading + azimuth_deg * kPi / 180.0;
  const Eigen::Vector3d source =
      listener_ + distance_m * Eigen::Vector3d(std::cos(world_angle), std::sin(world_angle), 0.0);
  // The paper's grid reaches 4 m in every direction; a source beyond a wall pushes that wall
  // out to just behind it, so the direct sound always arrives first.
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(config_.wall_margin);
  const Eigen::Vector3d lo = config_.room.min_corner.cwiseMin(source - margin);
  const Eigen::Vector3d hi = config_.room.max_corner.cwiseMax(source + margin);

  const int order = config_.max_order;
  std::vector<AxisImage> axes[3];
  for (int a = 0; a < 3; ++a) axes[a] = axis_images(source[a], lo[a], hi[a], order);

  struct Image {
    Eigen::Vector3d offset;
    int reflections;
  };
  std::vector<Image> images;
  double mixing_distance = std::numeric_limits<double>::infinity();
  for (const auto& ix : axes[0])
    for (const auto& iy : axes[1])
      for (const auto& iz : axes[2]) {
        const int count = ix.reflections + iy.reflections + iz.reflections;
        const Eigen::Vector3d offset =
            Eigen::Vector3d(ix.coordinate, iy.coordinate, iz.coordinate) - listener_;
        if (count <= order)
          images.push_back({offset, count});
        else if (count == order + 1)
          mixing_distance = std::min(mixing_distance, offset.norm());
      }
  // Up to the mixing distance every image of the lattice is present; later the tail takes over.
  const bool tail = config_.late_tail;

  const double fs = config_.sample_rate, c = config_.speed_of_sound;
  const double beta = std::sqrt(1.0 - absorption_);  // pressure reflection coefficient
  const double cos_h = std::cos(heading), sin_h = std::sin(heading);
  BinauralIr out{std::vector<float>(length_, 0.0f), std::vector<float>(length_, 0.0f)};
  float kernel[kFractionalTaps];
  for (const Image& image : images) {
    const double r = std::max(image.offset.norm(), 0.05);
    if (tail && r >= mixing_distance) continue;
    // Arrival direction in the head frame: rotate the world offset by -heading about z.
    const Eigen::Vector3d head(cos_h * image.offset.x() + sin_h * image.offset.y(),
                               -sin_h * image.offset.x() + cos_h * image.offset.y(),
                               image.offset.z());
    const BinauralIr& hrir = hrirs_.irs[hrirs_.nearest(head)];
    const double gain = std::pow(beta, image.reflections) / r;
    const double delay = r / c * fs;
    const long whole = static_cast<long>(std::floor(delay));
    const double frac = delay - whole;
    // Hann-windowed sinc centred on the fractional delay, normalised to unit DC gain.
    double sum = 0.0;
    for (int k = 0; k < kFractionalTaps; ++k) {
      const double x = (k - (kFractionalTaps / 2 - 1)) - frac;
      const double sinc = std::abs(x) < 1e-12 ? 1.0 : std::sin(kPi * x) / (kPi * x);
      const double window = 0.5 * (1.0 + std::cos(kPi * x / (kFractionalTaps / 2 + 0.5)));
      kernel[k] = static_cast<float>(sinc * window);
      sum += kernel[k];
    }
    for (auto& k : kernel) k = static_cast<float>(k / sum * gain);
    const long start = whole - (kFractionalTaps / 2 - 1);
    const size_t n = hrir.left.size();
    for (int k = 0; k < kFractionalTaps; ++k) {
      for (size_t m = 0; m < n; ++m) {
        const long i = start + k + static_cast<long>(m);
        if (i < 0 || i >= static_cast<long>(length_)) continue;
        out.left[i] += kernel[k] * hrir.left[m];
        out.right[i] += kernel[k] * hrir.right[m];
      }
    }
  }
  if (tail && std::isfinite(mixing_distance)) {
    const size_t start = static_cast<size_t>(std::ceil(mixing_distance / c * fs));
    const BinauralIr late = late_tail(azimuth_deg, distance_m, start);
    for (size_t i = start; i < length_; ++i) {
      out.left[i] += late.left[i];
      out.right[i] += late.right[i];
    }
  }
  return out;
}

BrirSet BrirSynthesizer::synthesize(const BrirGrid& grid, const StopRequested& stop) const {
  for (double d : grid.distances_m) check_source(0.0, d);  // before any work
  const size_t na = grid.azimuths_deg.size(), nd = grid.distances_m.size();
  std::vector<BinauralIr> irs(na * nd);
  tbb::parallel_for(size_t{0}, irs.size(), [&](size_t i) {
    if (stop && stop()) return;
    irs[i] = synthesize(grid.azimuths_deg[i % na], grid.distances_m[i / na]);
  });
  if (stop && stop()) return BrirSet{};  // skipped points: an empty set the caller discards
  return BrirSet(config_.sample_rate, grid, std::move(irs));
}

BrirSet BrirSynthesizer::synthesize_on_demand(std::shared_ptr<const BrirSynthesizer> self, const BrirGrid& grid,
                                              const StopRequested& stop) {
  for (double d : grid.distances_m) self->check_source(0.0, d);  // before any work
  const size_t na = grid.azimuths_deg.size(), nd = grid.distances_m.size();
  // The reference level: each point's loudest ear, kept in its own slot (the maximum does not
  // depend on the thread count), the response itself dropped.
  std::vector<double> loudest(na * nd);
  tbb::parallel_for(size_t{0}, loudest.size(), [&](size_t i) {
    if (stop && stop()) return;
    loudest[i] = loudest_ear_energy(self->synthesize(grid.azimuths_deg[i % na], grid.distances_m[i / na]));
  });
  if (stop && stop()) return BrirSet{};
  const double max_energy = *std::max_element(loudest.begin(), loudest.end());
  const double factor = max_energy > 0.0 ? 1.0 / std::sqrt(max_energy) : 1.0;
  auto make = [self, grid, factor](size_t d, size_t a) {
    BinauralIr ir = self->synthesize(grid.azimuths_deg[a], grid.distances_m[d]);
    if (factor != 1.0) scale(ir, factor);
    return ir;
  };
  return BrirSet(self->config_.sample_rate, grid, self->length(), make);
}

}  // namespace sonomap::audio
