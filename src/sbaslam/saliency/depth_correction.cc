#include "sbaslam/saliency/depth_correction.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam::saliency {
namespace {

bool valid_depth(float d) {
  return std::isfinite(d) && d > 0.0f;
}

float median_valid_depth(const cv::Mat& depth) {
  std::vector<float> values;
  values.reserve(depth.total());
  for (int y = 0; y < depth.rows; ++y) {
    const float* row = depth.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x)
      if (valid_depth(row[x])) values.push_back(row[x]);
  }
  if (values.empty()) return 0.0f;
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

bool every_depth_valid(const cv::Mat& depth) {
  for (int y = 0; y < depth.rows; ++y) {
    const float* row = depth.ptr<float>(y);
    if (!std::all_of(row, row + depth.cols, valid_depth)) return false;
  }
  return true;
}

// Orders filled cells by squared distance to the query, then by row and column: a fixed order for
// equally distant cells, so that the weighted sum does not depend on how they were found.
struct CellDistance {
  int squared;
  cv::Point cell;
  bool operator<(const CellDistance& o) const {
    if (squared != o.squared) return squared < o.squared;
    return cell.y != o.cell.y ? cell.y < o.cell.y : cell.x < o.cell.x;
  }
};

// The k filled cells nearest to `at`, searched ring by ring (Chebyshev distance r) and stopped once
// no cell of a further ring can be nearer than the k-th found: the grid's filled cells are
// usually a few cells away, where the brute-force scan visited all of them for every empty cell.
void nearest_filled_cells(const cv::Mat& count, cv::Point at, std::size_t k,
                          std::vector<CellDistance>& nearest) {
  nearest.clear();
  const int max_ring = std::max(count.cols, count.rows);
  auto visit = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= count.cols || y >= count.rows) return;
    if (count.at<int>(y, x) == 0) return;
    const int dx = x - at.x, dy = y - at.y;
    nearest.push_back({dx * dx + dy * dy, cv::Point(x, y)});
  };
  for (int r = 1; r <= max_ring; ++r) {
    for (int x = at.x - r; x <= at.x + r; ++x) {
      visit(x, at.y - r);
      visit(x, at.y + r);
    }
    for (int y = at.y - r + 1; y <= at.y + r - 1; ++y) {
      visit(at.x - r, y);
      visit(at.x + r, y);
    }
    if (nearest.size() < k) continue;
    std::nth_element(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(k - 1),
                     nearest.end());
    // Every cell of ring r + 1 is at least r + 1 away.
    if (nearest[k - 1].squared < (r + 1) * (r + 1)) break;
  }
  const std::size_t kept = std::min(k, nearest.size());
  std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(kept),
                    nearest.end());
  nearest.resize(kept);
}

}  // namespace

cv::Mat saturated_saliency(const cv::Mat& s_init, double saturation) {
  if (!(saturation > 0.0 && saturation <= 1.0))
    fail("saliency saturation must be in (0, 1], got {}", saturation);
  if (saturation == 1.0 || s_init.empty()) return s_init;
  cv::Mat out;
  s_init.convertTo(out, CV_8U, 1.0 / saturation);
  return out;
}

cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Mat& depth, double a, double b,
                                 double near_depth) {
  if (s_init.empty() || s_init.type() != CV_8UC1) fail("depth correction: S_init must be 8-bit");
  if (depth.empty() || depth.type() != CV_32FC1)
    fail("depth correction: depth must be CV_32F metres");
  cv::Mat d = depth;
  if (d.size() != s_init.size()) cv::resize(depth, d, s_init.size(), 0, 0, cv::INTER_NEAREST);
  // The median is needed only where a pixel lacks depth (never for a densified map).
  if (!every_depth_valid(d)) {
    const float fallback = median_valid_depth(d);
    if (fallback <= 0.0f) return s_init.clone();
    d = d.clone();
    for (int y = 0; y < d.rows; ++y) {
      float* row = d.ptr<float>(y);
      for (int x = 0; x < d.cols; ++x)
        if (!valid_depth(row[x])) row[x] = fallback;
    }
  }
  // S_hat is kept in a buffer reused across frames: a fresh image of doubles cost more in page
  // faults than the arithmetic, and computing it twice (maximum, then values) cost more divisions.
  thread_local std::vector<double> s_hat;
  s_hat.resize(s_init.total());
  double max_value = 0.0;
  const float near = static_cast<float>(near_depth);
  for (int y = 0; y < s_init.rows; ++y) {
    const std::uint8_t* s_row = s_init.ptr<std::uint8_t>(y);
    const float* d_row = d.ptr<float>(y);
    double* hat_row = s_hat.data() + static_cast<std::size_t>(y) * s_init.cols;
    for (int x = 0; x < s_init.cols; ++x) {
      hat_row[x] = std::max(0.0, a * (s_row[x] / 255.0) / std::max(d_row[x], near) + b);
      max_value = std::max(max_value, hat_row[x]);
    }
  }
  const double scale = max_value > 0.0 ? 255.0 / max_value : 0.0;
  cv::Mat out(s_init.size(), CV_8U);
  for (int y = 0; y < s_init.rows; ++y) {
    const double* hat_row = s_hat.data() + static_cast<std::size_t>(y) * s_init.cols;
    std::uint8_t* out_row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < s_init.cols; ++x)
      out_row[x] = cv::saturate_cast<std::uint8_t>(hat_row[x] * scale);
  }
  return out;
}

cv::Mat stereo_depth(const cv::Mat& left, const cv::Mat& right, double fx, double baseline,
                     int max_disparity) {
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size())
    fail("stereo depth: left and right must be 8-bit images of one size");
  if (fx <= 0 || baseline <= 0) fail("stereo depth: fx and baseline must be positive");
  const int num_disparities = std::max(16, (max_disparity + 15) / 16 * 16);
  const int block = 5;
  cv::Ptr<cv::StereoSGBM> sgbm =
      cv::StereoSGBM::create(0, num_disparities, block, 8 * block * block, 32 * block * block, 1,
                             63, 10, 100, 2, cv::StereoSGBM::MODE_SGBM);
  cv::Mat disparity16;
  sgbm->compute(left, right, disparity16);
  cv::Mat depth(left.size(), CV_32F, cv::Scalar(0));
  const double fb = fx * baseline;
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const double disparity = disparity16.at<std::int16_t>(y, x) / 16.0;  // fixed point 12.4
      if (disparity > 0.0) depth.at<float>(y, x) = static_cast<float>(fb / disparity);
    }
  return depth;
}

cv::Mat rgbd_depth(const cv::Mat& raw, double depth_map_factor) {
  if (depth_map_factor <= 0) fail("rgbd depth: DepthMapFactor must be positive");
  if (raw.channels() != 1) fail("rgbd depth: depth image must have one channel");
  cv::Mat depth;
  raw.convertTo(depth, CV_32F, 1.0 / depth_map_factor);
  return depth;
}

cv::Mat densify_sparse_depth(const std::vector<DepthSample>& samples, const cv::Size& size,
                             int cell, int neighbours) {
  if (cell <= 0 || neighbours <= 0) fail("densify depth: cell and neighbours must be positive");
  const cv::Size grid((size.width + cell - 1) / cell, (size.height + cell - 1) / cell);
  cv::Mat sum(grid, CV_64F, cv::Scalar(0)), count(grid, CV_32S, cv::Scalar(0));
  for (const DepthSample& s : samples) {
    if (!valid_depth(s.depth)) continue;
    const int gx = static_cast<int>(s.u) / cell, gy = static_cast<int>(s.v) / cell;
    if (s.u < 0 || s.v < 0 || gx >= grid.width || gy >= grid.height) continue;
    sum.at<double>(gy, gx) += s.depth;
    count.at<int>(gy, gx) += 1;
  }
  const int filled = cv::countNonZero(count);
  if (filled == 0) return cv::Mat(size, CV_32F, cv::Scalar(0));
  cv::Mat coarse(grid, CV_32F);
  const std::size_t k = std::min<std::size_t>(neighbours, filled);
  std::vector<CellDistance> nearest;
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x) {
      if (count.at<int>(y, x) > 0) {
        coarse.at<float>(y, x) = static_cast<float>(sum.at<double>(y, x) / count.at<int>(y, x));
        continue;
      }
      nearest_filled_cells(count, cv::Point(x, y), k, nearest);
      double weighted = 0.0, weights = 0.0;
      for (const CellDistance& n : nearest) {
        const double w = 1.0 / n.squared;  // squared distance > 0: the cell is empty
        weighted += w * sum.at<double>(n.cell.y, n.cell.x) / count.at<int>(n.cell.y, n.cell.x);
        weights += w;
      }
      coarse.at<float>(y, x) = static_cast<float>(weighted / weights);
    }
  cv::Mat dense;
  cv::resize(coarse, dense, cv::Size(grid.width * cell, grid.height * cell), 0, 0,
             cv::INTER_LINEAR);
  return dense(cv::Rect(cv::Point(0, 0), size)).clone();
}

double median_sample_depth(const std::vector<DepthSample>& samples) {
  if (samples.empty()) return 0.0;
  std::vector<float> depths;
  depths.reserve(samples.size());
  for (const DepthSample& s : samples) depths.push_back(s.depth);
  const auto middle = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return *middle;
}

cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Size& image_size,
                                 const std::vector<DepthSample>& keypoint_depths, double a,
                                 double b, double near_depth) {
  if (image_size.width <= 0 || image_size.height <= 0)
    fail("depth correction: empty image size {}x{}", image_size.width, image_size.height);
  const double sx = static_cast<double>(s_init.cols) / image_size.width;
  const double sy = static_cast<double>(s_init.rows) / image_size.height;
  std::vector<DepthSample> in_map;
  in_map.reserve(keypoint_depths.size());
  for (const DepthSample& d : keypoint_depths)
    in_map.push_back({static_cast<float>(d.u * sx), static_cast<float>(d.v * sy), d.depth});
  const int cell = std::max(2, s_init.cols / 40);
  return depth_corrected_saliency(s_init, densify_sparse_depth(in_map, s_init.size(), cell), a, b,
                                  near_depth);
}

}  // namespace sbaslam::saliency
