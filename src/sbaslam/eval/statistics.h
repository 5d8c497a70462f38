#pragma once
// The statistics evo prints, with numpy's conventions: population std, median averaging the
// two middle values for an even count.

#include <cstddef>
#include <vector>

namespace sbaslam::eval {

struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;
  std::size_t n = 0;
};

// Throws sbaslam::Error for an empty list or a non-finite error.
ErrorStatistics compute_statistics(const std::vector<double>& errors);

}  // namespace sbaslam::eval
