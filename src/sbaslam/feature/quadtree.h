#pragma once
// ORB-SLAM's quadtree distribution of keypoints: the region is cut into roughly square nodes,
// nodes holding more than one keypoint are split in four until there are as many nodes as wanted
// (the most populated nodes first in the last round), and each node keeps its strongest keypoint.
// The result spreads keypoints over the image instead of piling them on the most textured spot.

#include <opencv2/core/types.hpp>
#include <vector>

namespace sbaslam::feature {

class QuadtreeDistributor {
 public:
  // Returns, in `kept`, indices into `candidates` (x, y in [min, max] of the region; response is
  // the strength). Keeps one keypoint per final node: at least min(n_wanted, candidates) keypoints
  // when the candidates are distinct, possibly up to 3 more than n_wanted, as ORB-SLAM. The
  // buffers are reused between calls.
  void distribute(const std::vector<cv::KeyPoint>& candidates, const cv::Rect2f& region,
                  int n_wanted, std::vector<int>& kept);

 private:
  struct Node {
    float x0, y0, x1, y1;
    int begin, end;  // range in order_
    int size() const { return end - begin; }
  };

  void make_initial_nodes(const std::vector<cv::KeyPoint>& candidates, const cv::Rect2f& region);
  // Appends the non-empty quarters of `node` to `out`; returns how many of them hold > 1 point.
  int split(const Node& node, const std::vector<cv::KeyPoint>& candidates, std::vector<Node>& out);
  void split_largest_first(const std::vector<cv::KeyPoint>& candidates, int n_wanted);

  std::vector<int> order_;  // candidate indices, grouped so that each node is a contiguous range
  std::vector<Node> nodes_;
  std::vector<Node> next_;
  std::vector<int> by_size_;
  std::vector<char> split_flags_;
  std::vector<int> column_starts_, column_fill_;
};

}  // namespace sbaslam::feature
