#include "sbaslam/match/feature_grid.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::match {

FeatureGrid::FeatureGrid(const std::vector<feature::OrbKeypoint>& keypoints,
                         const cv::Rect2f& bounds, int cols, int rows)
    : bounds_(bounds), cols_(cols), rows_(rows) {
  if (cols < 1 || rows < 1 || !(bounds.width > 0.0f && bounds.height > 0.0f))
    fail("feature grid: needs positive cells ({}x{}) and bounds ({}x{})", cols, rows, bounds.width,
         bounds.height);
  inv_cell_w_ = static_cast<float>(cols) / bounds.width;
  inv_cell_h_ = static_cast<float>(rows) / bounds.height;
  const std::size_t n = keypoints.size();
  x_.resize(n);
  y_.resize(n);
  octave_.resize(n);
  std::vector<int> cell_of(n, -1);
  cell_starts_.assign(static_cast<std::size_t>(cols) * rows + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    x_[i] = keypoints[i].x;
    y_[i] = keypoints[i].y;
    octave_[i] = keypoints[i].octave;
    const float fx = (x_[i] - bounds.x) * inv_cell_w_, fy = (y_[i] - bounds.y) * inv_cell_h_;
    if (!(fx >= 0.0f && fy >= 0.0f)) continue;  // also skips NaN
    const auto cx = static_cast<int>(fx), cy = static_cast<int>(fy);
    if (cx >= cols || cy >= rows) continue;
    cell_of[i] = cy * cols + cx;
    ++cell_starts_[cell_of[i] + 1];
  }
  for (std::size_t c = 1; c < cell_starts_.size(); ++c) cell_starts_[c] += cell_starts_[c - 1];
  cell_entries_.resize(cell_starts_.back());
  std::vector<int> fill(cell_starts_.begin(), cell_starts_.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (cell_of[i] >= 0) cell_entries_[fill[cell_of[i]]++] = static_cast<int>(i);
}

void FeatureGrid::features_in_area(float x, float y, float r, int min_level, int max_level,
                                   std::vector<int>& out) const {
  out.clear();
  if (cols_ == 0 || !(r > 0.0f) || !std::isfinite(x) || !std::isfinite(y)) return;
  const int min_cx = std::max(0, static_cast<int>(std::floor((x - bounds_.x - r) * inv_cell_w_)));
  const int max_cx =
      std::min(cols_ - 1, static_cast<int>(std::ceil((x - bounds_.x + r) * inv_cell_w_)));
  const int min_cy = std::max(0, static_cast<int>(std::floor((y - bounds_.y - r) * inv_cell_h_)));
  const int max_cy =
      std::min(rows_ - 1, static_cast<int>(std::ceil((y - bounds_.y + r) * inv_cell_h_)));
  if (min_cx > max_cx || min_cy > max_cy) return;
  const bool check_levels = min_level > 0 || max_level >= 0;
  for (int cy = min_cy; cy <= max_cy; ++cy)
    for (int cx = min_cx; cx <= max_cx; ++cx) {
      const int cell = cy * cols_ + cx;
      for (int e = cell_starts_[cell]; e < cell_starts_[cell + 1]; ++e) {
        const int i = cell_entries_[e];
        if (check_levels && (octave_[i] < min_level || (max_level >= 0 && octave_[i] > max_level)))
          continue;
        if (std::abs(x_[i] - x) < r && std::abs(y_[i] - y) < r) out.push_back(i);
      }
    }
}

}  // namespace sbaslam::match
