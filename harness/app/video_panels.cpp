// SPDX-License-Identifier: GPL-3.0-or-later
#include "harness/app/video_panels.hpp"

#include <algorithm>
#include <cmath>

namespace sonomap::harness {
namespace {

constexpr double kPi = 3.14159265358979323846;
const Rgb kUnknown{0x60, 0x60, 0x60}, kHighlight{0xff, 0xd7, 0x00}, kInk{0xf0, 0xf0, 0xf0};

std::int64_t cell_key(long x, long y) { return (static_cast<std::int64_t>(x) << 32) ^ (y & 0xffffffffLL); }
long cell_x(std::int64_t key) { return static_cast<long>(key >> 32); }
long cell_y(std::int64_t key) { return static_cast<long>(static_cast<std::int32_t>(key & 0xffffffffLL)); }

// Screen offset of a bearing (ccw from ahead, degrees) at `radius` pixels: ahead up, left left.
void bearing_offset(double deg, double radius, double& dx, double& dy) {
  const double t = deg * kPi / 180.0;
  dx = -radius * std::sin(t);
  dy = -radius * std::cos(t);
}

}  // namespace

void draw_depth(Canvas& canvas, const PanelRect& r, const Frame& frame, double max_depth) {
  if (frame.width <= 0 || frame.height <= 0) return;
  const double scale = std::min(static_cast<double>(r.w) / frame.width, static_cast<double>(r.h) / frame.height);
  const int w = static_cast<int>(frame.width * scale), h = static_cast<int>(frame.height * scale);
  const int x0 = r.x + (r.w - w) / 2, y0 = r.y + (r.h - h) / 2;
  for (int y = 0; y < h; ++y) {
    const int sy = std::min(frame.height - 1, static_cast<int>(y / scale));
    for (int x = 0; x < w; ++x) {
      const int sx = std::min(frame.width - 1, static_cast<int>(x / scale));
      const float d = frame.depth[static_cast<size_t>(sy) * frame.width + sx];
      canvas.set(x0 + x, y0 + y, d > 0.0f ? range_colour(d / max_depth) : Rgb{0, 0, 0});
    }
  }
}

void draw_circle(Canvas& canvas, const PanelRect& r, const Circle& circle,
                 const RasterConfig& config, int sector, int sectors) {
  const double cx = r.x + r.w / 2.0, cy = r.y + r.h / 2.0;
  const double ring = 0.46 * std::min(r.w, r.h), inner = ring - 8.0;
  const double metres = (inner - 4.0) / config.max_range;  // pixels per metre inside the ring
  const int bins = circle.size();
  const int per_sector = sectors > 0 ? bins / sectors : 0;
  for (int k = 0; k < bins; ++k) {
    const RasterCell& cell = circle.bins[k];
    const bool played = per_sector > 0 && k / per_sector == sector;
    const Rgb colour = cell.known() ? range_colour(cell.range / config.max_range) : kUnknown;
    for (double a = k * circle.bin_width_deg(); a < (k + 1) * circle.bin_width_deg(); a += 0.25) {
      double dx, dy;
      bearing_offset(a, 1.0, dx, dy);
      canvas.line(cx + inner * dx, cy + inner * dy, cx + ring * dx, cy + ring * dy, colour);
      if (played) canvas.line(cx + (ring + 2) * dx, cy + (ring + 2) * dy, cx + (ring + 7) * dx,
                              cy + (ring + 7) * dy, kHighlight);
    }
    if (cell.known() && std::isfinite(cell.range)) {
      double dx, dy;
      bearing_offset(circle.bin_centre_deg(k), std::min<double>(cell.range, config.max_range) * metres, dx, dy);
      canvas.dot(cx + dx, cy + dy, played ? 3 : 1, played ? kHighlight : colour);
    }
  }
  if (per_sector > 0 && sector >= 0) {  // the played sector's two edges, from the listener
    for (int edge : {sector, sector + 1}) {
      double dx, dy;
      bearing_offset(edge * 360.0 / sectors, inner, dx, dy);
      canvas.line(cx, cy, cx + dx, cy + dy, kHighlight);
    }
  }
  canvas.dot(cx, cy, 4, kInk);
  canvas.line(cx, cy, cx, cy - 0.5 * metres, kInk);  // straight ahead, half a metre
}

void TopView::add_surface(const std::vector<Eigen::Vector3f>& points, double z_min, double z_max) {
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite() || p.z() < z_min || p.z() > z_max) continue;
    const long x = std::lround(p.x() / cell_m_), y = std::lround(p.y() / cell_m_);
    if (!cells_.insert(cell_key(x, y)).second) continue;
    extend(Eigen::Vector2d(x * cell_m_, y * cell_m_));
  }
}

void TopView::extend(const Eigen::Vector2d& p) {
  min_ = bounded_ ? min_.cwiseMin(p) : p;
  max_ = bounded_ ? max_.cwiseMax(p) : p;
  bounded_ = true;
}

void TopView::add_pose(const Eigen::Vector2d& position, double heading) {
  if (!position.allFinite()) return;
  path_.push_back(position);
  heading_ = heading;
  extend(position);
}

void TopView::draw(Canvas& canvas, const PanelRect& r) const {
  if (!bounded_) return;
  const Eigen::Vector2d lo = min_.array() - 0.5, size = (max_ - min_).array() + 1.0;
  const double scale = std::min((r.w - 8) / size.x(), (r.h - 8) / size.y());  // pixels per metre
  const double ox = r.x + (r.w - size.x() * scale) / 2, oy = r.y + (r.h + size.y() * scale) / 2;
  auto sx = [&](double x) { return ox + (x - lo.x()) * scale; };
  auto sy = [&](double y) { return oy - (y - lo.y()) * scale; };  // north (+y) up
  const int side = std::max(1, static_cast<int>(std::ceil(cell_m_ * scale)));  // cells touch
  for (std::int64_t key : cells_)
    canvas.fill_rect(static_cast<int>(std::floor(sx((cell_x(key) - 0.5) * cell_m_))),
                     static_cast<int>(std::floor(sy((cell_y(key) + 0.5) * cell_m_))), side, side,
                     {0xa0, 0xa0, 0xa0});
  for (size_t i = 1; i < path_.size(); ++i)
    canvas.line(sx(path_[i - 1].x()), sy(path_[i - 1].y()), sx(path_[i].x()), sy(path_[i].y()), kHighlight);
  if (path_.empty()) return;
  const Eigen::Vector2d& p = path_.back();
  canvas.dot(sx(p.x()), sy(p.y()), 4, kInk);
  canvas.line(sx(p.x()), sy(p.y()), sx(p.x() + 0.6 * std::cos(heading_)), sy(p.y() + 0.6 * std::sin(heading_)), kInk);
}

void draw_lines(Canvas& canvas, const PanelRect& r, const std::vector<std::string>& lines) {
  int y = r.y + 8;
  for (const std::string& line : lines) {
    canvas.text(r.x + 8, y, line, kInk, 2);
    y += 22;
  }
}

}  // namespace sonomap::harness
