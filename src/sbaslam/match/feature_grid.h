#pragma once
// A grid of cells over the (undistorted) image holding keypoint indices, for the radius queries
// of matching by projection (ORB-SLAM's mGrid and GetFeaturesInArea). The cells are stored in
// one index array with per-cell offsets, not a vector per cell.

#include <opencv2/core/types.hpp>
#include <vector>

#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::match {

class FeatureGrid {
 public:
  FeatureGrid() = default;
  // `keypoints` in the coordinates later queried (undistorted pixels); `bounds` is the image
  // region the cells cover (see feature::undistorted_image_bounds). Keypoints outside it are not
  // indexed. ORB-SLAM uses 64 x 48 cells.
  FeatureGrid(const std::vector<feature::OrbKeypoint>& keypoints, const cv::Rect2f& bounds,
              int cols = 64, int rows = 48);

  // Indices of the keypoints with |x - kp.x| < r and |y - kp.y| < r (a square window, as
  // ORB-SLAM) whose octave is >= min_level and, when max_level >= 0, <= max_level. Clears `out`.
  void features_in_area(float x, float y, float r, int min_level, int max_level,
                        std::vector<int>& out) const;
  std::vector<int> features_in_area(float x, float y, float r, int min_level = 0,
                                    int max_level = -1) const {
    std::vector<int> out;
    features_in_area(x, y, r, min_level, max_level, out);
    return out;
  }

  std::size_t size() const { return x_.size(); }
  const cv::Rect2f& bounds() const { return bounds_; }

 private:
  cv::Rect2f bounds_;
  int cols_ = 0, rows_ = 0;
  float inv_cell_w_ = 0.0f, inv_cell_h_ = 0.0f;
  std::vector<float> x_, y_;
  std::vector<int> octave_;
  std::vector<int> cell_starts_;  // cols * rows + 1
  std::vector<int> cell_entries_;
};

}  // namespace sbaslam::match
