#include "sbaslam/feature/quadtree.h"

#include <algorithm>
#include <cmath>

namespace sbaslam::feature {

void QuadtreeDistributor::make_initial_nodes(const std::vector<cv::KeyPoint>& candidates,
                                             const cv::Rect2f& region) {
  // Start from square-ish nodes side by side, so the first splits do not produce slivers on wide
  // images (KITTI is 3.3 times wider than tall).
  const int n_initial =
      std::max(1, static_cast<int>(std::lround(region.width / std::max(region.height, 1.0f))));
  const float node_width = region.width / static_cast<float>(n_initial);
  auto column_of = [&](const cv::KeyPoint& kp) {
    const int c = static_cast<int>((kp.pt.x - region.x) / node_width);
    return std::clamp(c, 0, n_initial - 1);
  };
  // Counting sort of the candidates by initial column.
  column_starts_.assign(n_initial + 1, 0);
  for (const cv::KeyPoint& kp : candidates) ++column_starts_[column_of(kp) + 1];
  for (int c = 0; c < n_initial; ++c) column_starts_[c + 1] += column_starts_[c];
  order_.resize(candidates.size());
  column_fill_.assign(column_starts_.begin(), column_starts_.end() - 1);
  for (std::size_t i = 0; i < candidates.size(); ++i)
    order_[column_fill_[column_of(candidates[i])]++] = static_cast<int>(i);
  nodes_.clear();
  for (int c = 0; c < n_initial; ++c) {
    if (column_starts_[c] == column_starts_[c + 1]) continue;
    const float x0 = region.x + node_width * static_cast<float>(c);
    nodes_.push_back({x0, region.y, x0 + node_width, region.y + region.height, column_starts_[c],
                      column_starts_[c + 1]});
  }
}

int QuadtreeDistributor::split(const Node& node, const std::vector<cv::KeyPoint>& candidates,
                               std::vector<Node>& out) {
  const float mx = 0.5f * (node.x0 + node.x1);
  const float my = 0.5f * (node.y0 + node.y1);
  int* first = order_.data() + node.begin;
  int* last = order_.data() + node.end;
  int* y_split = std::partition(first, last, [&](int i) { return candidates[i].pt.y < my; });
  int* top_split = std::partition(first, y_split, [&](int i) { return candidates[i].pt.x < mx; });
  int* bottom_split = std::partition(y_split, last, [&](int i) { return candidates[i].pt.x < mx; });
  const int base = node.begin;
  auto offset = [&](const int* p) { return base + static_cast<int>(p - first); };
  const Node quarters[4] = {
      {node.x0, node.y0, mx, my, node.begin, offset(top_split)},
      {mx, node.y0, node.x1, my, offset(top_split), offset(y_split)},
      {node.x0, my, mx, node.y1, offset(y_split), offset(bottom_split)},
      {mx, my, node.x1, node.y1, offset(bottom_split), node.end},
  };
  int expandable = 0;
  for (const Node& q : quarters) {
    if (q.size() == 0) continue;
    out.push_back(q);
    if (q.size() > 1) ++expandable;
  }
  return expandable;
}

void QuadtreeDistributor::split_largest_first(const std::vector<cv::KeyPoint>& candidates,
                                              int n_wanted) {
  for (;;) {
    const std::size_t previous = nodes_.size();
    by_size_.clear();
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      if (nodes_[i].size() > 1) by_size_.push_back(static_cast<int>(i));
    std::stable_sort(by_size_.begin(), by_size_.end(),
                     [&](int a, int b) { return nodes_[a].size() > nodes_[b].size(); });
    next_.clear();
    std::size_t count = nodes_.size();
    split_flags_.assign(nodes_.size(), 0);
    for (int i : by_size_) {
      const std::size_t before = next_.size();
      split(nodes_[i], candidates, next_);
      split_flags_[i] = 1;
      count += next_.size() - before - 1;
      if (count >= static_cast<std::size_t>(n_wanted)) break;
    }
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      if (!split_flags_[i]) next_.push_back(nodes_[i]);
    nodes_.swap(next_);
    if (nodes_.size() >= static_cast<std::size_t>(n_wanted) || nodes_.size() == previous) return;
  }
}

void QuadtreeDistributor::distribute(const std::vector<cv::KeyPoint>& candidates,
                                     const cv::Rect2f& region, int n_wanted,
                                     std::vector<int>& kept) {
  kept.clear();
  if (candidates.empty() || n_wanted <= 0) return;
  make_initial_nodes(candidates, region);

  // Split every node while the result cannot overshoot n_wanted by more than 3; then split the
  // most populated nodes first until n_wanted is reached (ORB-SLAM's two phases).
  for (;;) {
    const auto count = static_cast<int>(nodes_.size());
    const auto expandable = static_cast<int>(
        std::count_if(nodes_.begin(), nodes_.end(), [](const Node& n) { return n.size() > 1; }));
    if (count >= n_wanted || expandable == 0) break;
    if (count + 3 * expandable > n_wanted) {
      split_largest_first(candidates, n_wanted);
      break;
    }
    next_.clear();
    for (const Node& node : nodes_) {
      if (node.size() == 1)
        next_.push_back(node);
      else
        split(node, candidates, next_);
    }
    if (next_.size() == nodes_.size()) {  // only inseparable duplicates left
      nodes_.swap(next_);
      break;
    }
    nodes_.swap(next_);
  }

  kept.reserve(nodes_.size());
  for (const Node& node : nodes_) {
    int best = order_[node.begin];
    for (int k = node.begin + 1; k < node.end; ++k)
      if (candidates[order_[k]].response > candidates[best].response) best = order_[k];
    kept.push_back(best);
  }
}

}  // namespace sbaslam::feature
