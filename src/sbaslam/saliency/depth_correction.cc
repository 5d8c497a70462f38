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
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x)
      if (valid_depth(depth.at<float>(y, x))) values.push_back(depth.at<float>(y, x));
  if (values.empty()) return 0.0f;
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Mat& depth, double a, double b) {
  if (s_init.empty() || s_init.type() != CV_8UC1) fail("depth correction: S_init must be 8-bit");
  if (depth.empty() || depth.type() != CV_32FC1)
    fail("depth correction: depth must be CV_32F metres");
  cv::Mat d = depth;
  if (d.size() != s_init.size()) cv::resize(depth, d, s_init.size(), 0, 0, cv::INTER_NEAREST);
  const float fallback = median_valid_depth(d);
  if (fallback <= 0.0f) return s_init.clone();
  cv::Mat s_hat(s_init.size(), CV_64F);
  for (int y = 0; y < s_init.rows; ++y)
    for (int x = 0; x < s_init.cols; ++x) {
      const float dv = d.at<float>(y, x);
      const double s = s_init.at<std::uint8_t>(y, x) / 255.0;
      s_hat.at<double>(y, x) = std::max(0.0, a * s / (valid_depth(dv) ? dv : fallback) + b);
    }
  double max_value = 0.0;
  cv::minMaxLoc(s_hat, nullptr, &max_value);
  cv::Mat out;
  s_hat.convertTo(out, CV_8U, max_value > 0.0 ? 255.0 / max_value : 0.0);
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
  std::vector<cv::Point> filled;
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x)
      if (count.at<int>(y, x) > 0) filled.emplace_back(x, y);
  if (filled.empty()) return cv::Mat(size, CV_32F, cv::Scalar(0));
  cv::Mat coarse(grid, CV_32F);
  const std::size_t k = std::min<std::size_t>(neighbours, filled.size());
  std::vector<std::pair<double, cv::Point>> nearest(filled.size());
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x) {
      if (count.at<int>(y, x) > 0) {
        coarse.at<float>(y, x) = static_cast<float>(sum.at<double>(y, x) / count.at<int>(y, x));
        continue;
      }
      for (std::size_t i = 0; i < filled.size(); ++i) {
        const double dx = filled[i].x - x, dy = filled[i].y - y;
        nearest[i] = {dx * dx + dy * dy, filled[i]};
      }
      std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(k),
                        nearest.end(),
                        [](const auto& l, const auto& r) { return l.first < r.first; });
      double weighted = 0.0, weights = 0.0;
      for (std::size_t i = 0; i < k; ++i) {
        const cv::Point c = nearest[i].second;
        const double w = 1.0 / nearest[i].first;  // squared distance > 0: the cell is empty
        weighted += w * sum.at<double>(c.y, c.x) / count.at<int>(c.y, c.x);
        weights += w;
      }
      coarse.at<float>(y, x) = static_cast<float>(weighted / weights);
    }
  cv::Mat dense;
  cv::resize(coarse, dense, cv::Size(grid.width * cell, grid.height * cell), 0, 0,
             cv::INTER_LINEAR);
  return dense(cv::Rect(cv::Point(0, 0), size)).clone();
}

cv::Mat depth_corrected_saliency(const cv::Mat& s_init, const cv::Size& image_size,
                                 const std::vector<DepthSample>& keypoint_depths, double a,
                                 double b) {
  if (image_size.width <= 0 || image_size.height <= 0)
    fail("depth correction: empty image size {}x{}", image_size.width, image_size.height);
  const double sx = static_cast<double>(s_init.cols) / image_size.width;
  const double sy = static_cast<double>(s_init.rows) / image_size.height;
  std::vector<DepthSample> in_map;
  in_map.reserve(keypoint_depths.size());
  for (const DepthSample& d : keypoint_depths)
    in_map.push_back({static_cast<float>(d.u * sx), static_cast<float>(d.v * sy), d.depth});
  const int cell = std::max(2, s_init.cols / 40);
  return depth_corrected_saliency(s_init, densify_sparse_depth(in_map, s_init.size(), cell), a, b);
}

}  // namespace sbaslam::saliency
